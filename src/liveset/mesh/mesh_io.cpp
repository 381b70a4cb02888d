// Mesh writers (PLY/OBJ/STL, world coordinates, through the atomic file writer) and bounded readers.
#include "liveset/mesh/mesh_io.hpp"

#include "liveset/base/atomic_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace liveset {

namespace fs = std::filesystem;

namespace {

static_assert(std::endian::native == std::endian::little, "binary mesh I/O assumes a little-endian host");

[[noreturn]] void fail(const fs::path& path, const std::string& what) {
    throw std::runtime_error("mesh file " + path.string() + ": " + what);
}

std::string lower_ext(const fs::path& path) {
    std::string e = path.extension().string();
    for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

struct WorldVertex {
    float p[3];
    float n[3];
};

std::vector<WorldVertex> to_world(MeshView mesh, const Lattice& lattice) {
    std::vector<WorldVertex> out(mesh.vertices.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const Vertex& v = mesh.vertices[i];
        const Vec3d p = lattice.to_world({v.position[0], v.position[1], v.position[2]});
        const Vec3d n = lattice.direction_to_world({v.normal[0], v.normal[1], v.normal[2]});
        for (int k = 0; k < 3; ++k) {
            out[i].p[k] = static_cast<float>(p[k]);
            out[i].n[k] = static_cast<float>(n[k]);
        }
    }
    return out;
}

template <class T>
void put(std::ostream& os, T v) {
    os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

void write_ply_body(std::ostream& os, const std::vector<WorldVertex>& v, MeshView mesh) {
    os << "ply\nformat binary_little_endian 1.0\ncomment liveset marching cubes, world coordinates\n"
       << "element vertex " << v.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
       << "property float nx\nproperty float ny\nproperty float nz\n"
       << "element face " << mesh.triangle_count() << "\nproperty list uchar uint vertex_indices\nend_header\n";
    for (const WorldVertex& w : v) os.write(reinterpret_cast<const char*>(&w), sizeof(w));
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        put<std::uint8_t>(os, 3);
        for (int k = 0; k < 3; ++k) put<std::uint32_t>(os, mesh.indices[3 * t + k]);
    }
}

void write_obj_body(std::ostream& os, const std::vector<WorldVertex>& v, MeshView mesh) {
    os << "# liveset marching cubes, world coordinates\n";
    char buf[128];
    for (const WorldVertex& w : v) {
        std::snprintf(buf, sizeof buf, "v %.9g %.9g %.9g\n", w.p[0], w.p[1], w.p[2]);
        os << buf;
    }
    for (const WorldVertex& w : v) {
        std::snprintf(buf, sizeof buf, "vn %.9g %.9g %.9g\n", w.n[0], w.n[1], w.n[2]);
        os << buf;
    }
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint64_t a = mesh.indices[3 * t] + 1ull, b = mesh.indices[3 * t + 1] + 1ull,
                            c = mesh.indices[3 * t + 2] + 1ull;
        os << "f " << a << "//" << a << ' ' << b << "//" << b << ' ' << c << "//" << c << '\n';
    }
}

void write_stl_body(std::ostream& os, const std::vector<WorldVertex>& v, MeshView mesh) {
    char header[80] = {};
    std::snprintf(header, sizeof header, "liveset marching cubes, world coordinates");
    os.write(header, 80);
    put<std::uint32_t>(os, static_cast<std::uint32_t>(mesh.triangle_count()));
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const WorldVertex* c[3] = {&v[mesh.indices[3 * t]], &v[mesh.indices[3 * t + 1]], &v[mesh.indices[3 * t + 2]]};
        Vec3d p[3];
        for (int k = 0; k < 3; ++k) p[k] = {c[k]->p[0], c[k]->p[1], c[k]->p[2]};
        Vec3d n = cross(p[1] - p[0], p[2] - p[0]);
        if (!(norm(n) > 0)) {  // degenerate facet: average the vertex normals
            n = {};
            for (int k = 0; k < 3; ++k) n += Vec3d{c[k]->n[0], c[k]->n[1], c[k]->n[2]};
        }
        if (norm(n) > 0) n = n / norm(n);
        for (int k = 0; k < 3; ++k) put<float>(os, static_cast<float>(n[k]));
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) put<float>(os, c[k]->p[a]);
        put<std::uint16_t>(os, 0);
    }
}

void check_indices(const fs::path& path, MeshView mesh) {
    if (mesh.indices.size() % 3 != 0) fail(path, "index count is not a multiple of 3");
    for (std::uint32_t i : mesh.indices)
        if (i >= mesh.vertices.size()) fail(path, "triangle index out of range");
    if (mesh.triangle_count() > 0xFFFFFFFFull) fail(path, "too many triangles");
}

// Reads the whole file, refusing files above `limit` bytes.
std::string slurp(const fs::path& path, std::uintmax_t limit = std::uintmax_t{1} << 34) {
    std::error_code ec;
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec) fail(path, "cannot open (" + ec.message() + ")");
    if (size > limit) fail(path, "file too large");
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open for reading");
    std::string data(static_cast<std::size_t>(size), '\0');
    in.read(data.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::uintmax_t>(in.gcount()) != size) fail(path, "read error");
    return data;
}

template <class T>
T get(const std::string& data, std::size_t& at) {
    T v;
    std::memcpy(&v, data.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
}

int scalar_size(const std::string& type) {
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
        return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

bool parse_double(std::string_view s, double& out) {
    const char* end = s.data() + s.size();
    auto [ptr, ec] = std::from_chars(s.data(), end, out);
    return ec == std::errc() && ptr == end && std::isfinite(out);
}

}  // namespace

MeshFormat mesh_format_for_path(const fs::path& path) {
    const std::string e = lower_ext(path);
    if (e == ".ply") return MeshFormat::ply;
    if (e == ".obj") return MeshFormat::obj;
    if (e == ".stl") return MeshFormat::stl;
    throw std::invalid_argument("unsupported mesh file extension '" + e + "' for " + path.string() +
                                " (use .ply, .obj or .stl)");
}

void write_mesh(const fs::path& path, MeshView mesh, const Lattice& lattice) {
    write_mesh(path, mesh, lattice, mesh_format_for_path(path));
}

void write_mesh(const fs::path& path, MeshView mesh, const Lattice& lattice, MeshFormat format) {
    check_indices(path, mesh);
    const std::vector<WorldVertex> world = to_world(mesh, lattice);
    try {
        write_file_atomically(path, [&](std::ostream& os) {
            switch (format) {
                case MeshFormat::ply: write_ply_body(os, world, mesh); break;
                case MeshFormat::obj: write_obj_body(os, world, mesh); break;
                case MeshFormat::stl: write_stl_body(os, world, mesh); break;
            }
        });
    } catch (const std::runtime_error& e) {
        fail(path, e.what());
    }
}

namespace {

// A binary PLY header: the element counts, the vertex properties and whether faces are lists.
struct PlyProperty {
    std::string name;
    int size;
    std::string type;
};
struct PlyHeader {
    std::size_t end = 0;  // offset of "end_header\n"
    std::uint64_t vertices = 0, faces = 0;
    bool binary_le = false, face_list = false;
    std::vector<PlyProperty> vertex_properties;
};

PlyHeader parse_ply_header(const fs::path& path, const std::string& data) {
    PlyHeader h;
    h.end = data.find("end_header\n");
    if (data.compare(0, 4, "ply\n") != 0 || h.end == std::string::npos || h.end > (1u << 16))
        fail(path, "not a PLY file (missing 'ply' or 'end_header')");
    std::istringstream header(data.substr(0, h.end));
    std::string line, element;
    while (std::getline(header, line)) {
        std::istringstream ls(line);
        std::string word;
        ls >> word;
        if (word == "format") {
            std::string fmt, ver;
            ls >> fmt >> ver;
            h.binary_le = fmt == "binary_little_endian";
        } else if (word == "element") {
            std::uint64_t n = 0;
            ls >> element >> n;
            if (!ls) fail(path, "malformed element line");
            if (element == "vertex") h.vertices = n;
            else if (element == "face") h.faces = n;
            else fail(path, "unsupported element '" + element + "'");
        } else if (word == "property") {
            std::string type;
            ls >> type;
            if (element == "vertex") {
                std::string name;
                ls >> name;
                const int sz = scalar_size(type);
                if (!ls || sz == 0) fail(path, "malformed vertex property");
                h.vertex_properties.push_back({name, sz, type});
            } else if (element == "face") {
                std::string ct, it, name;
                ls >> ct >> it >> name;
                if (type != "list" || !ls) fail(path, "face property must be a list");
                if (scalar_size(ct) != 1 || (scalar_size(it) != 4 || it == "float" || it == "float32"))
                    fail(path, "unsupported face list types");
                h.face_list = true;
            } else {
                fail(path, "property outside an element");
            }
        } else if (word != "ply" && word != "comment" && word != "obj_info" && !word.empty()) {
            fail(path, "unexpected header line '" + line + "'");
        }
    }
    return h;
}

}  // namespace

Mesh read_ply(const fs::path& path) {
    const std::string data = slurp(path);
    const PlyHeader h = parse_ply_header(path, data);
    const std::uint64_t nv = h.vertices, nf = h.faces;
    const std::vector<PlyProperty>& vprops = h.vertex_properties;
    const std::size_t header_end = h.end;
    if (!h.binary_le) fail(path, "only binary_little_endian PLY is supported");
    if (nf > 0 && !h.face_list) fail(path, "face element without a vertex list");
    int ix[6] = {-1, -1, -1, -1, -1, -1};
    const char* names[6] = {"x", "y", "z", "nx", "ny", "nz"};
    std::size_t stride = 0;
    std::vector<std::size_t> offset;
    for (std::size_t i = 0; i < vprops.size(); ++i) {
        offset.push_back(stride);
        stride += static_cast<std::size_t>(vprops[i].size);
        for (int k = 0; k < 6; ++k)
            if (vprops[i].name == names[k]) {
                if (vprops[i].type != "float" && vprops[i].type != "float32" && vprops[i].type != "double" &&
                    vprops[i].type != "float64")
                    fail(path, "coordinates must be float or double");
                ix[k] = static_cast<int>(i);
            }
    }
    if (ix[0] < 0 || ix[1] < 0 || ix[2] < 0) fail(path, "vertex element lacks x, y or z");
    std::size_t at = header_end + std::strlen("end_header\n");
    const std::uint64_t remaining = data.size() - at;
    if (nv > 0xFFFFFFFFull || nf > remaining / 13 + 1 || (stride > 0 && nv > remaining / stride))
        fail(path, "element counts do not fit the file");
    Mesh m;
    m.vertices.resize(nv);
    for (std::uint64_t i = 0; i < nv; ++i) {
        float vals[6] = {0, 0, 0, 0, 0, 0};
        for (int k = 0; k < 6; ++k) {
            if (ix[k] < 0) continue;
            std::size_t p = at + offset[static_cast<std::size_t>(ix[k])];
            vals[k] = vprops[static_cast<std::size_t>(ix[k])].size == 8 ? static_cast<float>(get<double>(data, p))
                                                                         : get<float>(data, p);
        }
        std::memcpy(m.vertices[i].position, vals, 3 * sizeof(float));
        std::memcpy(m.vertices[i].normal, vals + 3, 3 * sizeof(float));
        at += stride;
    }
    m.indices.reserve(3 * nf);
    for (std::uint64_t f = 0; f < nf; ++f) {
        if (at + 1 > data.size()) fail(path, "truncated face data");
        const auto n = get<std::uint8_t>(data, at);
        if (n != 3) fail(path, "only triangular faces are supported");
        if (at + 12 > data.size()) fail(path, "truncated face data");
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t idx = get<std::uint32_t>(data, at);
            if (idx >= nv) fail(path, "face index out of range");
            m.indices.push_back(idx);
        }
    }
    if (at != data.size()) fail(path, "trailing data after the faces");
    return m;
}

namespace {

using ObjCorner = std::pair<std::uint32_t, std::uint32_t>;  // (v, vn) of a face corner; vn UINT32_MAX: none

// The corners of an OBJ face line ("f 1 2 3", "f 1//4 2//5 3//6", negative indices count back).
std::vector<ObjCorner> parse_obj_face(std::istringstream& ls, std::size_t positions, std::size_t normals,
                                      const std::function<void(const std::string&)>& bad) {
    std::vector<ObjCorner> poly;
    std::string tok;
    while (ls >> tok) {
        long long vi = 0, ni = 0;
        const std::size_t s1 = tok.find('/');
        auto to_int = [&](std::string_view sv, long long& out) {
            auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), out);
            if (ec != std::errc() || p != sv.data() + sv.size()) bad("malformed face index '" + tok + "'");
        };
        to_int(std::string_view(tok).substr(0, s1), vi);
        if (s1 != std::string::npos) {
            const std::size_t s2 = tok.find('/', s1 + 1);
            if (s2 != std::string::npos && s2 + 1 < tok.size()) to_int(std::string_view(tok).substr(s2 + 1), ni);
        }
        auto resolve = [&](long long i, std::size_t n) -> long long {
            if (i < 0) i += static_cast<long long>(n) + 1;
            if (i < 1 || i > static_cast<long long>(n)) bad("face index out of range");
            return i - 1;
        };
        const auto v = static_cast<std::uint32_t>(resolve(vi, positions));
        const std::uint32_t nn = ni == 0 ? UINT32_MAX : static_cast<std::uint32_t>(resolve(ni, normals));
        poly.push_back({v, nn});
    }
    if (poly.size() < 3) bad("face with fewer than 3 vertices");
    return poly;
}

// Vertex i is position i with the first normal it is used with; other normals split it into extra
// vertices appended after all positions.
Mesh assemble_obj(const std::vector<std::array<float, 3>>& pos, const std::vector<std::array<float, 3>>& nrm,
                  const std::vector<ObjCorner>& corners) {
    Mesh m;
    std::map<ObjCorner, std::uint32_t> ids;
    m.vertices.resize(pos.size());
    std::vector<std::uint32_t> first_normal(pos.size(), UINT32_MAX - 1);
    for (std::size_t i = 0; i < pos.size(); ++i) std::memcpy(m.vertices[i].position, pos[i].data(), sizeof(float) * 3);
    m.indices.reserve(corners.size());
    for (const auto& [v, nn] : corners) {
        std::uint32_t id = v;
        if (first_normal[v] == UINT32_MAX - 1) {
            first_normal[v] = nn;
            if (nn != UINT32_MAX) std::memcpy(m.vertices[v].normal, nrm[nn].data(), sizeof(float) * 3);
        } else if (first_normal[v] != nn) {
            auto [it, inserted] = ids.try_emplace({v, nn}, static_cast<std::uint32_t>(m.vertices.size()));
            if (inserted) {
                Vertex vx{};
                std::memcpy(vx.position, pos[v].data(), sizeof vx.position);
                if (nn != UINT32_MAX) std::memcpy(vx.normal, nrm[nn].data(), sizeof vx.normal);
                m.vertices.push_back(vx);
            }
            id = it->second;
        }
        m.indices.push_back(id);
    }
    return m;
}

}  // namespace

Mesh read_obj(const fs::path& path) {
    const std::string data = slurp(path);
    std::vector<std::array<float, 3>> pos, nrm;
    std::vector<ObjCorner> corners;  // three per triangle (polygons are fanned)
    std::istringstream in(data);
    std::string line;
    std::size_t lineno = 0;
    const std::function<void(const std::string&)> bad = [&](const std::string& what) {
        fail(path, "line " + std::to_string(lineno) + ": " + what);
    };
    while (std::getline(in, line)) {
        ++lineno;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag.empty() || tag[0] == '#' || tag == "o" || tag == "g" || tag == "s" || tag == "mtllib" || tag == "usemtl" ||
            tag == "vt")
            continue;
        if (tag == "v" || tag == "vn") {
            std::array<float, 3> v{};
            for (float& c : v) {
                std::string tok;
                double d = 0.0;
                if (!(ls >> tok) || !parse_double(tok, d)) bad("malformed " + tag);
                c = static_cast<float>(d);
            }
            (tag == "v" ? pos : nrm).push_back(v);
        } else if (tag == "f") {
            const std::vector<ObjCorner> poly = parse_obj_face(ls, pos.size(), nrm.size(), bad);
            for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
                corners.push_back(poly[0]);
                corners.push_back(poly[i]);
                corners.push_back(poly[i + 1]);
            }
        } else {
            bad("unsupported statement '" + tag + "'");
        }
    }
    return assemble_obj(pos, nrm, corners);
}

Mesh read_stl(const fs::path& path) {
    const std::string data = slurp(path);
    if (data.size() < 84) fail(path, "too short for a binary STL");
    std::size_t at = 80;
    const auto n = get<std::uint32_t>(data, at);
    if (data.size() != 84 + 50ull * n) fail(path, "size does not match the triangle count (ASCII STL is not supported)");
    Mesh m;
    m.vertices.reserve(3ull * n);
    m.indices.reserve(3ull * n);
    for (std::uint32_t t = 0; t < n; ++t) {
        float nv[3];
        for (float& c : nv) c = get<float>(data, at);
        for (int k = 0; k < 3; ++k) {
            Vertex v{};
            for (float& c : v.position) c = get<float>(data, at);
            std::memcpy(v.normal, nv, sizeof nv);
            m.indices.push_back(static_cast<std::uint32_t>(m.vertices.size()));
            m.vertices.push_back(v);
        }
        at += 2;
    }
    return m;
}

Mesh read_mesh(const fs::path& path) {
    switch (mesh_format_for_path(path)) {
        case MeshFormat::ply: return read_ply(path);
        case MeshFormat::obj: return read_obj(path);
        case MeshFormat::stl: return read_stl(path);
    }
    fail(path, "unknown format");
}

}  // namespace liveset
