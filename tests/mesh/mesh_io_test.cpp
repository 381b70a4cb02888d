// Mesh export/import: PLY/OBJ/STL round trips in world coordinates on a lattice with non-unit
// spacing, origin and a rotated direction, atomic writes, and rejection of malformed files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "mesh/mesh_test_fields.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;

class MeshIo : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = testing::scratch_dir("mesh_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        // 90° rotation about z, anisotropic spacing, offset origin.
        lattice_ = Lattice({20, 18, 16}, {0.5, 0.8, 1.25}, {-10.0, 3.0, 7.5}, Mat3d{0, -1, 0, 1, 0, 0, 0, 0, 1});
        Grid<float> phi = testing::sphere_field({20, 18, 16}, {9.6, 8.7, 7.4}, 5.5);
        mesh_ = marching_cubes_naive(phi);
        ASSERT_GT(mesh_.triangle_count(), 100u);
    }
    void TearDown() override { fs::remove_all(dir_); }

    Vec3d world(const Vertex& v) const { return lattice_.to_world({v.position[0], v.position[1], v.position[2]}); }
    Vec3d world_normal(const Vertex& v) const {
        return lattice_.direction_to_world({v.normal[0], v.normal[1], v.normal[2]});
    }
    static Vec3d p3(const float* p) { return {p[0], p[1], p[2]}; }

    bool only_final_file_in_dir() const {
        int n = 0;
        for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir_)) ++n;
        return n == 1;
    }

    fs::path dir_;
    Lattice lattice_;
    Mesh mesh_;
};

// PLY and OBJ keep the indexed structure: compare vertex by vertex.
TEST_F(MeshIo, PlyAndObjRoundTripInWorldCoordinates) {
    for (const char* name : {"m.ply", "m.OBJ"}) {
        const fs::path path = dir_ / name;
        write_mesh(path, mesh_, lattice_);
        EXPECT_TRUE(only_final_file_in_dir());
        const Mesh r = read_mesh(path);
        ASSERT_EQ(r.vertices.size(), mesh_.vertices.size()) << name;
        ASSERT_EQ(r.indices, mesh_.indices) << name;
        for (std::size_t i = 0; i < r.vertices.size(); ++i) {
            const Vec3d want = world(mesh_.vertices[i]);
            ASSERT_LT(norm(p3(r.vertices[i].position) - want), 1e-5 * (1 + norm(want))) << name;
            ASSERT_LT(norm(p3(r.vertices[i].normal) - world_normal(mesh_.vertices[i])), 1e-6) << name;
        }
        // World mapping really applied: index-space and world positions differ.
        EXPECT_GT(norm(p3(r.vertices[0].position) - p3(mesh_.vertices[0].position)), 1.0);
        fs::remove(path);
    }
}

TEST_F(MeshIo, StlRoundTripAndWorldMeasures) {
    const fs::path path = dir_ / "m.stl";
    write_mesh(path, mesh_, lattice_, MeshFormat::stl);
    EXPECT_TRUE(only_final_file_in_dir());
    EXPECT_EQ(fs::file_size(path), 84 + 50 * mesh_.triangle_count());
    const Mesh r = read_stl(path);
    ASSERT_EQ(r.triangle_count(), mesh_.triangle_count());
    for (std::size_t t = 0; t < r.indices.size(); ++t) {
        const Vec3d want = world(mesh_.vertices[mesh_.indices[t]]);
        ASSERT_LT(norm(p3(r.vertices[r.indices[t]].position) - want), 1e-5 * (1 + norm(want)));
    }
    // Facet normals agree with the outward vertex normals, and the welded world mesh encloses
    // the index-space volume times the voxel volume (0.5 * 0.8 * 1.25 = 0.5; rotation keeps it).
    const Mesh w = weld_vertices(r, 1e-5);
    EXPECT_TRUE(edge_stats(w).closed_manifold());
    EXPECT_NEAR(enclosed_volume(w), 0.5 * enclosed_volume(mesh_), 1e-3 * enclosed_volume(mesh_));
    for (std::size_t t = 0; t < r.indices.size(); t += 3) {
        const Vec3d fn = p3(r.vertices[r.indices[t]].normal);
        EXPECT_GT(dot(fn, world_normal(mesh_.vertices[mesh_.indices[t]])), 0.0);
    }
}

TEST_F(MeshIo, OverwritesAtomicallyAndReportsPath) {
    const fs::path path = dir_ / "m.ply";
    write_mesh(path, mesh_, lattice_);
    write_mesh(path, Mesh{}, lattice_);  // replaced by an empty mesh
    EXPECT_EQ(read_ply(path).vertices.size(), 0u);
    EXPECT_TRUE(only_final_file_in_dir());
    const fs::path missing = dir_ / "no_such_dir" / "m.ply";
    try {
        write_mesh(missing, mesh_, lattice_);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos);
    }
    EXPECT_THROW(write_mesh(dir_ / "m.xyz", mesh_, lattice_), std::invalid_argument);
    EXPECT_THROW(read_mesh(dir_ / "absent.obj"), std::runtime_error);
    Mesh broken = mesh_;
    broken.indices.push_back(static_cast<std::uint32_t>(broken.vertices.size()));
    broken.indices.push_back(0);
    broken.indices.push_back(0);
    EXPECT_THROW(write_mesh(dir_ / "b.ply", broken, lattice_), std::runtime_error);
    EXPECT_TRUE(only_final_file_in_dir());
}

TEST_F(MeshIo, ReadersRejectMalformedFiles) {
    auto write_raw = [&](const std::string& name, const std::string& bytes) {
        std::ofstream(dir_ / name, std::ios::binary) << bytes;
        return dir_ / name;
    };
    EXPECT_THROW(read_ply(write_raw("a.ply", "not a ply")), std::runtime_error);
    EXPECT_THROW(read_ply(write_raw("b.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n")),
                 std::runtime_error);
    // Claims far more vertices than the file holds.
    EXPECT_THROW(read_ply(write_raw("c.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                                             "property float x\nproperty float y\nproperty float z\nend_header\n")),
                 std::runtime_error);
    // Truncated copy of a valid file.
    write_mesh(dir_ / "full.ply", mesh_, lattice_);
    std::ifstream in(dir_ / "full.ply", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_THROW(read_ply(write_raw("d.ply", bytes.substr(0, bytes.size() - 5))), std::runtime_error);
    EXPECT_THROW(read_obj(write_raw("e.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n")), std::runtime_error);
    EXPECT_THROW(read_obj(write_raw("f.obj", "v 0 0 nan\n")), std::runtime_error);
    EXPECT_THROW(read_obj(write_raw("g.obj", "v 0 0 0\nbogus\n")), std::runtime_error);
    EXPECT_THROW(read_stl(write_raw("h.stl", std::string(84, '\0') + "x")), std::runtime_error);
    EXPECT_THROW(read_stl(write_raw("i.stl", "solid x")), std::runtime_error);
    // A quad in OBJ is accepted and fan-triangulated.
    const Mesh q = read_obj(write_raw("q.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"));
    EXPECT_EQ(q.triangle_count(), 2u);
    // A position used with two normals is split; indices keep the file's numbering otherwise.
    const Mesh s = read_obj(write_raw("s.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0 -1\n"
                                               "f 1//1 2//1 3//1\nf 1//2 3//2 2//2\n"));
    EXPECT_EQ(s.vertices.size(), 6u);
    EXPECT_EQ(s.indices, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(s.vertices[4].position[1], 1.0f);  // position 3 (0,1,0) with normal 2
    EXPECT_EQ(s.vertices[5].normal[2], -1.0f);
    EXPECT_DOUBLE_EQ(surface_area(q), 1.0);
}

}  // namespace
}  // namespace liveset
