// A .mnc input end to end: the phantom on an oblique, anisotropic, off-centre lattice, given as
// NIfTI and as MINC1 (nii2mnc) and MINC2 (mincconvert -2), segmented from seeds in voxels and in
// LPS mm. Every run must segment the same voxels and write masks with the same affine and meshes
// in the same place; the mask headers are checked by minc-tools (nii2mnc + mincinfo against the
// input .mnc), and a .mnc mask written by liveset by mincinfo, worldtovoxel/mincextract (the seeds
// lie inside) and mnc2nii. MINC's world is RAS: without liveset's RAS <-> LPS conversion the
// masks and meshes lie mirrored and the seeds in mm miss the image.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "io/minc_tools.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/mesh_io.hpp"

namespace fs = std::filesystem;
using namespace liveset;
using liveset::testing::expect_same_place;
using liveset::testing::minc_tool;
using liveset::testing::minc_value_at;
using liveset::testing::minc_world;
using liveset::testing::MincWorld;
using liveset::testing::run_cli;
using liveset::testing::shell_quote;
using liveset::testing::slurp;
using Result = liveset::testing::CliResult;

namespace {

class MincCli : public liveset::testing::MincFolderTest {
protected:
    MincCli() : MincFolderTest("minc_cli_") {}
};

// The phantom's voxels on an oblique lattice whose axes run roughly left-to-right,
// posterior-to-anterior and inferior-to-superior (as MINC stores them: nii2mnc keeps their order
// and signs), 1.1 x 0.9 x 1.2 mm, far from the origin.
Lattice oblique_lattice(Vec3i dims) {
    const double t = 9.0 * std::acos(-1.0) / 180.0, c = std::cos(t), s = std::sin(t);
    // Rotation about z by 9 degrees, then about x by 9 degrees, of LPS diag(-1, -1, 1).
    const Mat3d rz{c, -s, 0, s, c, 0, 0, 0, 1}, rx{1, 0, 0, 0, c, -s, 0, s, c};
    Mat3d r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) r[std::size_t(i * 3 + j)] += rx[std::size_t(i * 3 + k)] * rz[std::size_t(k * 3 + j)];
    Mat3d d = r;
    for (int i = 0; i < 3; ++i) {
        d[std::size_t(i * 3 + 0)] = -r[std::size_t(i * 3 + 0)];
        d[std::size_t(i * 3 + 1)] = -r[std::size_t(i * 3 + 1)];
    }
    return Lattice(dims, {1.1, 0.9, 1.2}, {41.5, -17.25, 9.0}, d);
}

void expect_same_voxel_to_world(const Lattice& a, const Lattice& b, double tol_mm = 0.01) {
    EXPECT_EQ(a.dims(), b.dims());
    for (int c = 0; c < 4; ++c) {  // the origin and the three axes
        const Vec3d e{double(c == 1), double(c == 2), double(c == 3)};
        EXPECT_LT(norm(a.to_world(e) - b.to_world(e)), tol_mm) << "voxel " << e;
    }
}

// Inputs for the runs: the oblique phantom as in.nii (liveset's NIfTI writer), in1.mnc (nii2mnc:
// MINC1) and in2.mnc (mincconvert -2: MINC2), with the phantom's seeds as flags in voxels (the
// inputs share their voxel order: nii2mnc keeps these axes) and in LPS mm.
struct Inputs {
    Lattice lattice;
    std::string nii, minc1, minc2, seed_flags, seed_mm_flags;  // --seed I,J,K and --seed-mm X,Y,Z
    std::vector<Vec3i> seed_voxels;
    std::vector<Vec3d> seed_mm;
};

Inputs make_inputs(const fs::path& dir) {
    Inputs in;
    const Result ph = run_cli("phantom --size 48 --quiet --out " + (dir / "phantom").string());
    EXPECT_EQ(ph.rc, 0) << ph.err;
    const Grid<float> phantom = read_image((dir / "phantom/t1.nii.gz").string());
    Grid<float> image(oblique_lattice(phantom.dims()));
    for (PointIndex i = 0; i < image.size(); ++i) image[i] = phantom[i];
    in.lattice = image.lattice();
    in.nii = (dir / "in.nii").string();
    in.minc1 = (dir / "in1.mnc").string();
    in.minc2 = (dir / "in2.mnc").string();
    write_image(image, in.nii);
    minc_tool("nii2mnc -quiet " + shell_quote(in.nii) + " " + shell_quote(in.minc1));
    minc_tool("mincconvert -2 " + shell_quote(in.minc1) + " " + shell_quote(in.minc2));
    const nlohmann::json description = nlohmann::json::parse(slurp(dir / "phantom/phantom.json"));
    for (const auto& s : description["seeds"]) {
        const Vec3i v{s[0].get<int>(), s[1].get<int>(), s[2].get<int>()};
        const Vec3d mm = in.lattice.to_world(v.cast<double>());
        in.seed_voxels.push_back(v);
        in.seed_mm.push_back(mm);
        in.seed_flags += " --seed " + std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
        in.seed_mm_flags += " --seed-mm " + std::to_string(mm.x) + "," + std::to_string(mm.y) + "," + std::to_string(mm.z);
    }
    EXPECT_FALSE(in.seed_voxels.empty());
    return in;
}

double max_distance(const Mesh& a, const Mesh& b) {
    double worst = 0;
    for (std::size_t i = 0; i < a.vertices.size(); ++i) {
        const float* p = a.vertices[i].position;
        const float* q = b.vertices[i].position;
        worst = std::max(worst, std::hypot(double(p[0] - q[0]), double(p[1] - q[1]), double(p[2] - q[2])));
    }
    return worst;
}

void expect_same_minc_world(const MincWorld& a, const MincWorld& b, const std::string& what) {
    EXPECT_LT(norm(a.origin - b.origin), 0.01) << what << ": origin " << a.origin << " vs " << b.origin;
    for (std::size_t k = 0; k < 3; ++k)
        EXPECT_LT(norm(a.axis[k] - b.axis[k]), 0.01) << what << ": axis " << k << " " << a.axis[k] << " vs " << b.axis[k];
}

}  // namespace

TEST_F(MincCli, SegmentOfMincInputMatchesTheNiftiInput) {
    const Inputs in = make_inputs(dir_);
    ASSERT_FALSE(HasFailure());
    const std::vector<std::string> inputs = {in.nii, in.minc1, in.minc2};
    // Also with N4 first: NIfTI stores the voxel size in float (1.2000000477 mm), MINC in double
    // (1.1999999552 mm here), and N4's fit once turned that into masks a few voxels apart.
    for (const std::string bias : {"", " --bias-correct"}) {
        SCOPED_TRACE(bias.empty() ? "without N4" : "with N4");
        std::vector<Grid<std::uint8_t>> masks;
        std::vector<Mesh> meshes;
        for (std::size_t k = 0; k < inputs.size(); ++k) {
            const std::string n = std::to_string(k) + (bias.empty() ? "" : "_n4");
            const Result r = run_cli("segment " + shell_quote(inputs[k]) + in.seed_flags + bias + " --iterations 80 --quiet --out-mask " +
                                     path("mask" + n + ".nii") + " --out-mesh " + path("mesh" + n + ".ply"));
            ASSERT_EQ(r.rc, 0) << inputs[k] << ": " << r.err;
            masks.push_back(read_label_image(path("mask" + n + ".nii")));
            meshes.push_back(read_mesh(path("mesh" + n + ".ply")));
        }
        // The NIfTI run is the reference: its mask holds the seeds and lies on the input's lattice.
        std::size_t inside = 0;
        for (auto v : masks[0].values()) inside += v;
        EXPECT_GT(inside, 100u);
        for (const Vec3i v : in.seed_voxels) EXPECT_EQ(masks[0](v), 1) << "seed " << v;
        expect_same_voxel_to_world(masks[0].lattice(), in.lattice);

        // The same voxels, affines and meshes from the .mnc inputs.
        const MincWorld input_world = minc_world(in.minc1);
        for (std::size_t k = 1; k < inputs.size(); ++k) {
            SCOPED_TRACE(inputs[k]);
            expect_same_voxel_to_world(masks[0].lattice(), masks[k].lattice());
            ASSERT_EQ(masks[k].size(), masks[0].size());
            for (PointIndex i = 0; i < masks[0].size(); ++i) ASSERT_EQ(masks[k][i], masks[0][i]) << i;
            ASSERT_EQ(meshes[k].vertices.size(), meshes[0].vertices.size());
            EXPECT_EQ(meshes[k].indices, meshes[0].indices);
            EXPECT_LT(max_distance(meshes[k], meshes[0]), 0.01) << "mesh vertices moved (mm)";
            // minc-tools' own reading of the mask's NIfTI header: where they put the input .mnc.
            const std::string n = std::to_string(k) + (bias.empty() ? "" : "_n4");
            minc_tool("nii2mnc -quiet " + shell_quote(path("mask" + n + ".nii")) + " " + shell_quote(path("mask" + n + ".mnc")));
            expect_same_minc_world(minc_world(path("mask" + n + ".mnc")), input_world, "mask header");
        }
    }
}

// Seeds in LPS mm land on the same voxels for the .nii and the .mnc inputs (the masks are the same);
// minc-tools find them inside a .mnc mask written by liveset, which mincinfo places where the input
// .mnc lies and whose mnc2nii NIfTI holds the NIfTI run's mask voxels.
TEST_F(MincCli, SeedsInMillimetresLandOnTheSameVoxelsAndMincMaskIsPlacedRight) {
    const Inputs in = make_inputs(dir_);
    ASSERT_FALSE(HasFailure());
    const std::string common = in.seed_mm_flags + " --iterations 80 --quiet --out-mask ";
    const Result from_nii = run_cli("segment " + shell_quote(in.nii) + common + path("ref.nii"));
    ASSERT_EQ(from_nii.rc, 0) << from_nii.err;
    const Result from_minc1 = run_cli("segment " + shell_quote(in.minc1) + common + path("mask1.nii"));
    ASSERT_EQ(from_minc1.rc, 0) << from_minc1.err;
    const Result from_minc2 = run_cli("segment " + shell_quote(in.minc2) + common + path("mask.mnc"));
    ASSERT_EQ(from_minc2.rc, 0) << from_minc2.err;
    const Grid<std::uint8_t> ref = read_label_image(path("ref.nii")), mask1 = read_label_image(path("mask1.nii"));
    for (const Vec3i v : in.seed_voxels) EXPECT_EQ(ref(v), 1) << "seed " << v;
    ASSERT_EQ(mask1.size(), ref.size());
    for (PointIndex i = 0; i < ref.size(); ++i) ASSERT_EQ(mask1[i], ref[i]) << i;

    expect_same_minc_world(minc_world(path("mask.mnc")), minc_world(in.minc2), "mask.mnc");
    const Vec3d s = in.lattice.spacing();
    for (const Vec3d mm : in.seed_mm)
        EXPECT_EQ(minc_value_at(path("mask.mnc"), mm, std::min({s.x, s.y, s.z})), 1.0) << "seed at LPS " << mm;
    minc_tool("mnc2nii -quiet " + shell_quote(path("mask.mnc")) + " " + shell_quote(path("back.nii")));
    expect_same_place(ref, read_label_image(path("back.nii")));
}
