// MINC placement, checked with minc-tools (independent of ITK): NIfTI files converted by nii2mnc
// (MINC1) and mincconvert (MINC2, and back to MINC1) read by liveset land voxel for voxel where the
// NIfTI lies, in LPS; voxels looked up by their LPS position in minc-tools (worldtovoxel on the RAS
// position, then mincextract) hold liveset's values; and the .mnc files liveset writes are placed
// right by mincinfo, worldtovoxel and mnc2nii. MINC's world is RAS: without liveset's conversion
// every one of these checks finds the image mirrored in x and y.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/minc_tools.hpp"
#include "liveset/io/image_io.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;
using testing::expect_same_place;
using testing::minc_tool;
using testing::minc_value_at;
using testing::minc_world;
using testing::missing_minc_tools;
using testing::numbers;
using testing::ras_lps;
using testing::shell_quote;
using testing::rotation;

// A fresh folder per test; fails the test up front when minc-tools are missing.
class Minc : public testing::MincFolderTest {
protected:
    Minc() : MincFolderTest("minc_") {}
};


Mat3d product(const Mat3d& a, const Mat3d& b) {
    Mat3d p{};
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) p[std::size_t(r * 3 + c)] += a[std::size_t(r * 3 + k)] * b[std::size_t(k * 3 + c)];
    return p;
}

// Oblique, anisotropic, off-centre geometries (LPS direction matrices). "ras_aligned": the axes run
// roughly left-to-right, posterior-to-anterior, inferior-to-superior, as MINC stores them.
// "permuted": axis 0 runs right-to-left, axis 1 top-down and axis 2 front-to-back. (nii2mnc 2.3
// misplaces NIfTI files with permuted axes (wrong starts, found with nibabel), so the MINC files
// with permuted, reversed dimensions below are made by mincreshape instead.)
Lattice ras_aligned_lattice() {
    const Mat3d ras_axes{-1, 0, 0, 0, -1, 0, 0, 0, 1};
    return Lattice({10, 12, 8}, {1.5, 0.8, 2.2}, {37.5, -21.25, 12.0}, product(rotation({1, 2, 3}, 12), ras_axes));
}
Lattice permuted_lattice() {
    const Mat3d axes{1, 0, 0, 0, 0, -1, 0, -1, 0};
    return Lattice({10, 12, 8}, {1.5, 0.8, 2.2}, {-31.0, 17.5, 40.25}, product(rotation({3, -1, 2}, 10), axes));
}

// Distinct, asymmetric content: a voxel's value encodes its index.
Grid<float> coded_image(const Lattice& lattice) {
    Grid<float> g(lattice);
    for (PointIndex i = 0; i < g.size(); ++i) {
        const Vec3i p = lattice.coord(i);
        g[i] = float(p.x + 16 * p.y + 256 * p.z) + 0.5f;
    }
    return g;
}

std::string magic(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    char m[4] = {};
    in.read(m, 4);
    return std::string(m, 4);
}
bool is_minc1(const std::string& file) { return magic(file).substr(0, 3) == "CDF"; }    // NetCDF
bool is_minc2(const std::string& file) { return magic(file) == std::string("\x89HDF", 4); }  // HDF5

double min_spacing(const Lattice& l) { return std::min({l.spacing().x, l.spacing().y, l.spacing().z}); }

// Samples (the eight corners and a few inside) of `image`, read from `file`, looked up by their LPS
// position in minc-tools: same value.
void expect_minc_tools_agree(const std::string& file, const Grid<float>& image) {
    const Vec3i d = image.dims();
    std::vector<Vec3i> samples;
    for (int c = 0; c < 8; ++c) samples.push_back({c & 1 ? d.x - 1 : 0, c & 2 ? d.y - 1 : 0, c & 4 ? d.z - 1 : 0});
    for (int k = 1; k <= 4; ++k) samples.push_back({k * d.x / 5, (5 - k) * d.y / 5, (k * 3 % 5) * d.z / 5});
    for (const Vec3i p : samples) {
        const Vec3d lps = image.lattice().to_world(p.cast<double>());
        EXPECT_EQ(minc_value_at(file, lps, min_spacing(image.lattice())), double(image(p)))
            << file << ": voxel " << p << " at LPS " << lps;
    }
}

void expect_same_voxel_to_world(const Lattice& a, const Lattice& b, double tol_mm = 0.01) {
    EXPECT_EQ(a.dims(), b.dims());
    EXPECT_LT(norm(a.origin() - b.origin()), tol_mm) << a.origin() << " vs " << b.origin();
    for (int c = 0; c < 3; ++c) {
        const Vec3d ca = a.to_world(Vec3d{double(c == 0), double(c == 1), double(c == 2)}) - a.origin();
        const Vec3d cb = b.to_world(Vec3d{double(c == 0), double(c == 1), double(c == 2)}) - b.origin();
        EXPECT_LT(norm(ca - cb), tol_mm) << "axis " << c << ": " << ca << " vs " << cb;
    }
}

// An oblique NIfTI converted by nii2mnc (MINC1), by mincconvert to MINC2 and back to MINC1, and by
// mincreshape to files whose dimensions are stored in another order (x, z, y) with x and z
// reversed (MINC1 and MINC2): all read in the NIfTI's place.
TEST_F(Minc, NiftiConvertedToMinc1AndMinc2ReadsInTheSamePlace) {
    const Grid<float> image = coded_image(ras_aligned_lattice());
    const std::string nii = path("in.nii"), m1 = path("in1.mnc"), m2 = path("in2.mnc"), m1b = path("in1b.mnc"),
                      r1 = path("reshaped1.mnc"), r2 = path("reshaped2.mnc");
    write_image(image, nii);
    minc_tool("nii2mnc -quiet " + shell_quote(nii) + " " + shell_quote(m1));
    minc_tool("mincconvert -2 " + shell_quote(m1) + " " + shell_quote(m2));
    minc_tool("mincconvert " + shell_quote(m2) + " " + shell_quote(m1b));  // MINC2 back to MINC1
    minc_tool("mincreshape -quiet -float -dimorder xspace,zspace,yspace -xdirection -zdirection " + shell_quote(m1) +
              " " + shell_quote(r1));
    minc_tool("mincconvert -2 " + shell_quote(r1) + " " + shell_quote(r2));
    EXPECT_TRUE(is_minc1(m1));
    EXPECT_TRUE(is_minc2(m2));
    EXPECT_TRUE(is_minc1(m1b));
    EXPECT_TRUE(is_minc1(r1));
    EXPECT_TRUE(is_minc2(r2));
    EXPECT_NE(minc_tool("mincinfo -vardims image " + shell_quote(r2)).find("xspace zspace yspace"), std::string::npos);
    EXPECT_LT(numbers(minc_tool("mincinfo -attvalue xspace:step " + shell_quote(r2))).at(0), 0);
    const Grid<float> from_nii = read_image(nii);
    expect_same_voxel_to_world(from_nii.lattice(), image.lattice(), 1e-4);
    for (const std::string& file : {m1, m2, m1b, r1, r2}) {
        SCOPED_TRACE(file);
        const Grid<float> from_mnc = read_image(file);
        EXPECT_EQ(read_image_header(file).format, "MINC");
        expect_same_place(from_nii, from_mnc);
        // ITK reads x, y, z with positive steps: here the NIfTI's axes, voxel-to-world map and order.
        expect_same_voxel_to_world(from_nii.lattice(), from_mnc.lattice());
        for (PointIndex i = 0; i < from_nii.size(); ++i) ASSERT_EQ(from_mnc[i], from_nii[i]) << i;
        expect_minc_tools_agree(file, from_mnc);
    }
}

// Our MINC writer: mincinfo's RAS voxel-to-world map is the RAS form of the lattice, minc-tools find
// every sampled value where the lattice puts it, and mnc2nii's NIfTI lies where the image does.
TEST_F(Minc, WrittenMincIsPlacedRightByMincTools) {
    for (const bool permuted : {false, true}) {
        const Grid<float> image = coded_image(permuted ? permuted_lattice() : ras_aligned_lattice());
        const std::string out = path("out.mnc"), back = path("back.nii"), minc1 = path("out1.mnc");
        write_image(image, out);
        EXPECT_TRUE(is_minc2(out));
        const testing::MincWorld w = minc_world(out);
        const Lattice& l = image.lattice();
        EXPECT_LT(norm(ras_lps(w.origin) - l.origin()), 0.01) << w.origin << " is not the RAS of " << l.origin();
        for (int a = 0; a < 3; ++a) {
            const Vec3d col = l.to_world(Vec3d{double(a == 0), double(a == 1), double(a == 2)}) - l.origin();
            EXPECT_LT(norm(ras_lps(w.axis[std::size_t(a)]) - col), 0.01) << "axis " << a;
        }
        expect_minc_tools_agree(out, image);
        minc_tool("mnc2nii -quiet " + shell_quote(out) + " " + shell_quote(back));
        expect_same_place(image, read_image(back));
        minc_tool("mincconvert " + shell_quote(out) + " " + shell_quote(minc1));
        EXPECT_TRUE(is_minc1(minc1));
        expect_minc_tools_agree(minc1, read_image(minc1));
        fs::remove(out);
        fs::remove(back);
        fs::remove(minc1);
    }
    // Labels (uint8) the same way.
    Grid<std::uint8_t> labels(permuted_lattice());
    for (PointIndex i = 0; i < labels.size(); ++i) labels[i] = static_cast<std::uint8_t>((i * 37u) % 251u);
    write_label_image(labels, path("labels.mnc"));
    minc_tool("mnc2nii -quiet " + shell_quote(path("labels.mnc")) + " " + shell_quote(path("labels.nii")));
    expect_same_place(labels, read_label_image(path("labels.nii")));
    expect_same_place(labels, read_label_image(path("labels.mnc")));
}

// Real anatomy (asymmetric left to right): BrainWeb's labels as MINC read where the NIfTI lies.
TEST_F(Minc, BrainWebLabelsConvertedByNii2mnc) {
    const std::string nii = std::string(LIVESET_DATA_DIR) + "/brainweb/labels_crisp.nii.gz";
    ASSERT_TRUE(fs::exists(nii)) << "no BrainWeb data: " << nii;
    const std::string mnc = path("labels.mnc");
    minc_tool("nii2mnc -quiet -byte -unsigned " + shell_quote(nii) + " " + shell_quote(mnc));
    const Grid<std::uint8_t> from_nii = read_label_image(nii), from_mnc = read_label_image(mnc);
    expect_same_place(from_nii, from_mnc);
    Grid<float> as_float(from_mnc.lattice());
    for (PointIndex i = 0; i < as_float.size(); ++i) as_float[i] = from_mnc[i];
    expect_minc_tools_agree(mnc, as_float);
}

}  // namespace
}  // namespace liveset
