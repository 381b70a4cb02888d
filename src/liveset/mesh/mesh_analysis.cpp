// Mesh analysis utilities: welding, edge statistics, topology (Euler characteristic, components,
// pinched vertices), area, enclosed volume, normal checks and canonical triangle sets.
#include "liveset/mesh/mesh_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "liveset/grid/vec3.hpp"

namespace liveset {

namespace {

QuantisedPoint quantise(const Vertex& v, double quantum) {
    return {std::llround(v.position[0] / quantum), std::llround(v.position[1] / quantum),
            std::llround(v.position[2] / quantum)};
}

struct PointHash {
    std::size_t operator()(const QuantisedPoint& p) const {
        std::uint64_t h = 1469598103934665603ull;
        for (std::int64_t c : p) {
            h ^= static_cast<std::uint64_t>(c);
            h *= 1099511628211ull;
            h ^= h >> 29;
        }
        return static_cast<std::size_t>(h);
    }
};

struct UnionFind {
    std::vector<std::uint32_t> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t a) {
        while (parent[a] != a) a = parent[a] = parent[parent[a]];
        return a;
    }
    void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// Directed half-edges keyed by their undirected edge, sorted.
struct HalfEdge {
    std::uint64_t key;  // min << 32 | max
    bool forward;       // traversed min -> max
    bool operator<(const HalfEdge& o) const { return key < o.key || (key == o.key && forward < o.forward); }
};

std::vector<HalfEdge> half_edges(MeshView mesh) {
    std::vector<HalfEdge> h;
    h.reserve(mesh.indices.size());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t a = mesh.indices[t + k], b = mesh.indices[t + (k + 1) % 3];
            if (a == b) continue;
            const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
            h.push_back({(std::uint64_t{lo} << 32) | hi, a < b});
        }
    }
    std::sort(h.begin(), h.end());
    return h;
}

Vec3d pos(const Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

}  // namespace

Mesh weld_vertices(MeshView mesh, double quantum) {
    std::unordered_map<QuantisedPoint, std::uint32_t, PointHash> ids;
    ids.reserve(mesh.vertices.size());
    std::vector<std::uint32_t> remap(mesh.vertices.size());
    std::vector<std::uint32_t> first;  // representative original vertex per welded id
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        auto [it, inserted] = ids.try_emplace(quantise(mesh.vertices[i], quantum), static_cast<std::uint32_t>(first.size()));
        if (inserted) first.push_back(static_cast<std::uint32_t>(i));
        remap[i] = it->second;
    }
    Mesh out;
    std::vector<std::uint32_t> compact(first.size(), UINT32_MAX);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = remap[mesh.indices[t]], b = remap[mesh.indices[t + 1]], c = remap[mesh.indices[t + 2]];
        if (a == b || b == c || a == c) continue;
        for (std::uint32_t w : {a, b, c}) {
            if (compact[w] == UINT32_MAX) {
                compact[w] = static_cast<std::uint32_t>(out.vertices.size());
                out.vertices.push_back(mesh.vertices[first[w]]);
            }
            out.indices.push_back(compact[w]);
        }
    }
    return out;
}

EdgeStats edge_stats(MeshView mesh) {
    EdgeStats s;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const std::uint32_t a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        if (a == b || b == c || a == c) ++s.degenerate_triangles;
    }
    const std::vector<HalfEdge> h = half_edges(mesh);
    for (std::size_t i = 0; i < h.size();) {
        std::size_t j = i;
        std::size_t fwd = 0;
        while (j < h.size() && h[j].key == h[i].key) fwd += h[j++].forward ? 1 : 0;
        const std::size_t n = j - i;
        ++s.edges;
        if (n == 1) ++s.boundary_edges;
        if (n >= 3) ++s.nonmanifold_edges;
        if (n == 2 && fwd != 1) ++s.misoriented_edges;
        i = j;
    }
    return s;
}

std::vector<std::array<std::uint32_t, 2>> edges_not_shared_by_two(MeshView mesh) {
    std::vector<std::array<std::uint32_t, 2>> out;
    const std::vector<HalfEdge> h = half_edges(mesh);
    for (std::size_t i = 0; i < h.size();) {
        std::size_t j = i;
        while (j < h.size() && h[j].key == h[i].key) ++j;
        if (j - i != 2)
            out.push_back({static_cast<std::uint32_t>(h[i].key >> 32), static_cast<std::uint32_t>(h[i].key & 0xFFFFFFFFu)});
        i = j;
    }
    return out;
}

long long euler_characteristic(MeshView mesh) {
    std::vector<std::uint32_t> verts(mesh.indices.begin(), mesh.indices.end());
    std::sort(verts.begin(), verts.end());
    const auto v = static_cast<long long>(std::unique(verts.begin(), verts.end()) - verts.begin());
    const EdgeStats s = edge_stats(mesh);
    return v - static_cast<long long>(s.edges) + static_cast<long long>(mesh.triangle_count());
}

std::size_t connected_components(MeshView mesh) {
    UnionFind uf(mesh.vertices.size());
    std::vector<bool> used(mesh.vertices.size(), false);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        uf.unite(mesh.indices[t], mesh.indices[t + 1]);
        uf.unite(mesh.indices[t], mesh.indices[t + 2]);
        used[mesh.indices[t]] = used[mesh.indices[t + 1]] = used[mesh.indices[t + 2]] = true;
    }
    std::size_t n = 0;
    for (std::uint32_t i = 0; i < used.size(); ++i)
        if (used[i] && uf.find(i) == i) ++n;
    return n;
}

std::size_t nonmanifold_vertices(MeshView mesh) {
    struct Corner {
        std::uint32_t v, b, c;
    };
    std::vector<Corner> corners;
    corners.reserve(mesh.indices.size());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        for (int k = 0; k < 3; ++k)
            corners.push_back({mesh.indices[t + k], mesh.indices[t + (k + 1) % 3], mesh.indices[t + (k + 2) % 3]});
    std::sort(corners.begin(), corners.end(), [](const Corner& x, const Corner& y) { return x.v < y.v; });
    std::size_t bad = 0;
    std::vector<std::uint32_t> link;
    for (std::size_t i = 0; i < corners.size();) {
        std::size_t j = i;
        while (j < corners.size() && corners[j].v == corners[i].v) ++j;
        link.clear();
        for (std::size_t k = i; k < j; ++k) {
            link.push_back(corners[k].b);
            link.push_back(corners[k].c);
        }
        std::sort(link.begin(), link.end());
        link.erase(std::unique(link.begin(), link.end()), link.end());
        UnionFind uf(link.size());
        auto local = [&](std::uint32_t x) {
            return static_cast<std::uint32_t>(std::lower_bound(link.begin(), link.end(), x) - link.begin());
        };
        for (std::size_t k = i; k < j; ++k) uf.unite(local(corners[k].b), local(corners[k].c));
        std::size_t comps = 0;
        for (std::uint32_t k = 0; k < link.size(); ++k)
            if (uf.find(k) == k) ++comps;
        if (comps != 1) ++bad;
        i = j;
    }
    return bad;
}

double surface_area(MeshView mesh) {
    double area = 0;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vec3d a = pos(mesh.vertices[mesh.indices[t]]), b = pos(mesh.vertices[mesh.indices[t + 1]]),
                    c = pos(mesh.vertices[mesh.indices[t + 2]]);
        area += 0.5 * norm(cross(b - a, c - a));
    }
    return area;
}

double enclosed_volume(MeshView mesh) {
    double vol = 0;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vec3d a = pos(mesh.vertices[mesh.indices[t]]), b = pos(mesh.vertices[mesh.indices[t + 1]]),
                    c = pos(mesh.vertices[mesh.indices[t + 2]]);
        vol += dot(a, cross(b, c));
    }
    return vol / 6.0;
}

std::size_t invalid_normal_count(MeshView mesh, double tol) {
    std::size_t bad = 0;
    for (const Vertex& v : mesh.vertices) {
        const Vec3d n{v.normal[0], v.normal[1], v.normal[2]};
        const double len = norm(n);
        if (!all_finite(n) || !std::isfinite(len) || std::abs(len - 1.0) > tol) ++bad;
    }
    return bad;
}

std::size_t invalid_position_count(MeshView mesh) {
    std::size_t bad = 0;
    for (const Vertex& v : mesh.vertices)
        if (!all_finite(pos(v))) ++bad;
    return bad;
}

std::vector<CanonicalTriangle> canonical_triangles(MeshView mesh, double quantum) {
    std::vector<CanonicalTriangle> out;
    out.reserve(mesh.triangle_count());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        CanonicalTriangle tri{quantise(mesh.vertices[mesh.indices[t]], quantum),
                              quantise(mesh.vertices[mesh.indices[t + 1]], quantum),
                              quantise(mesh.vertices[mesh.indices[t + 2]], quantum)};
        const auto first = std::min_element(tri.begin(), tri.end()) - tri.begin();
        std::rotate(tri.begin(), tri.begin() + first, tri.end());
        out.push_back(tri);
    }
    std::sort(out.begin(), out.end());
    return out;
}

Mesh concatenate(const std::vector<MeshView>& parts) {
    Mesh out;
    std::size_t nv = 0, ni = 0;
    for (const MeshView& p : parts) {
        nv += p.vertices.size();
        ni += p.indices.size();
    }
    out.vertices.reserve(nv);
    out.indices.reserve(ni);
    for (const MeshView& p : parts) {
        const auto base = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.insert(out.vertices.end(), p.vertices.begin(), p.vertices.end());
        for (std::uint32_t i : p.indices) out.indices.push_back(base + i);
    }
    return out;
}

}  // namespace liveset
