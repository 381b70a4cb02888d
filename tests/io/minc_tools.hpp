// Test helpers that check MINC geometry with minc-tools (Debian's minc-tools, installed by
// scripts/setup.sh), independently of ITK: running the tools, MINC's voxel-to-world map from
// mincinfo, single voxels by world position (worldtovoxel + mincextract), and a voxel-by-voxel
// comparison of two grids by physical position (for files whose axes a converter reordered).
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "scratch_dir.hpp"

namespace liveset::testing {

struct ToolRun {
    int rc = -1;
    std::string out;  // stdout and stderr together
};

// Runs a shell command line, capturing its output.
inline ToolRun run_tool(const std::string& command) {
    ToolRun r;
    FILE* pipe = ::popen((command + " 2>&1 </dev/null").c_str(), "r");
    if (!pipe) return r;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
    const int status = ::pclose(pipe);
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    return r;
}

inline std::string shell_quote(const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// Empty when every minc-tools program the tests use is on PATH, else the message to fail with.
inline std::string missing_minc_tools() {
    std::string missing;
    for (const char* tool : {"nii2mnc", "mnc2nii", "mincconvert", "mincinfo", "worldtovoxel", "mincextract"})
        if (run_tool(std::string("command -v ") + tool).rc != 0) missing += std::string(" ") + tool;
    if (missing.empty()) return {};
    return "minc-tools are missing (" + missing.substr(1) +
           "): these tests check MINC geometry with them; run scripts/setup.sh (Debian package minc-tools)";
}

// Runs a minc-tools command and fails the test (returning its output anyway) when it fails.
inline std::string minc_tool(const std::string& command) {
    const ToolRun r = run_tool(command);
    EXPECT_EQ(r.rc, 0) << command << "\n" << r.out;
    return r.out;
}

inline std::vector<double> numbers(const std::string& text) {
    std::istringstream in(text);
    std::vector<double> v;
    for (double x; in >> x;) v.push_back(x);
    return v;
}

// MINC's own voxel-to-world map (RAS) as mincinfo reads it: column a is the xspace / yspace /
// zspace axis (step times direction cosines), origin the world position of voxel (0,0,0), whatever
// the order and signs of the dimensions in the file.
struct MincWorld {
    std::array<Vec3d, 3> axis;  // x, y, z space
    Vec3d origin{0, 0, 0};
};

inline MincWorld minc_world(const std::string& file) {
    MincWorld w;
    const char* names[3] = {"xspace", "yspace", "zspace"};
    for (int a = 0; a < 3; ++a) {
        const std::string dim = names[a], q = std::string(" ").append(shell_quote(file));
        const std::vector<double> step = numbers(minc_tool("mincinfo -attvalue " + dim + ":step" + q));
        const std::vector<double> start = numbers(minc_tool("mincinfo -attvalue " + dim + ":start" + q));
        const ToolRun cos = run_tool("mincinfo -attvalue " + dim + ":direction_cosines" + q);
        std::vector<double> c = cos.rc == 0 ? numbers(cos.out) : std::vector<double>{};
        if (c.size() != 3) c = {double(a == 0), double(a == 1), double(a == 2)};  // MINC's default
        EXPECT_EQ(step.size(), 1u) << file << " " << dim;
        EXPECT_EQ(start.size(), 1u) << file << " " << dim;
        if (step.size() != 1 || start.size() != 1) return w;
        const Vec3d u{c[0], c[1], c[2]};
        w.axis[std::size_t(a)] = u * step[0];
        w.origin = w.origin + u * start[0];
    }
    return w;
}

inline Vec3d ras_lps(Vec3d p) { return {-p.x, -p.y, p.z}; }  // the same map both ways

// The value minc-tools find at world position `lps` (converted to MINC's RAS): worldtovoxel must
// land within 0.01 mm of a voxel centre of `file`, whose value mincextract then reads.
inline double minc_value_at(const std::string& file, Vec3d lps, double min_spacing) {
    const Vec3d ras = ras_lps(lps);
    std::ostringstream cmd;
    cmd.precision(17);
    cmd << "worldtovoxel " << shell_quote(file) << " " << ras.x << " " << ras.y << " " << ras.z;
    const std::vector<double> v = numbers(minc_tool(cmd.str()));
    EXPECT_EQ(v.size(), 3u) << cmd.str();
    if (v.size() != 3) return std::nan("");
    std::string start;
    for (double c : v) {
        EXPECT_NEAR(c, std::round(c), 0.01 / min_spacing) << "LPS " << lps << " is not at a voxel centre of " << file;
        if (!start.empty()) start += ',';
        start += std::to_string(std::lround(c));
    }
    const std::vector<double> value = numbers(
        minc_tool("mincextract -double -ascii -start " + start + " -count 1,1,1 " + shell_quote(file)));
    EXPECT_EQ(value.size(), 1u) << file << " voxel " << start;
    return value.size() == 1 ? value[0] : std::nan("");
}

// Every voxel of `got` has a voxel of `ref` at the same physical position (within `tol_mm`) and the
// same value, one to one: `got` is `ref` in the same place, its axes possibly permuted or reversed.
template <class T>
void expect_same_place(const Grid<T>& ref, const Grid<T>& got, double tol_mm = 0.01) {
    ASSERT_EQ(ref.size(), got.size()) << ref.lattice().describe() << " vs " << got.lattice().describe();
    std::vector<char> hit(ref.size(), 0);
    std::size_t misplaced = 0, wrong = 0;
    for (PointIndex q = 0; q < got.size(); ++q) {
        const Vec3d w = got.lattice().to_world(got.lattice().coord(q).template cast<double>());
        const Vec3d c = ref.lattice().to_index(w);
        const Vec3i r{int(std::lround(c.x)), int(std::lround(c.y)), int(std::lround(c.z))};
        if (!ref.lattice().contains(r) || norm(ref.lattice().to_world(r.cast<double>()) - w) > tol_mm) {
            if (!misplaced++) ADD_FAILURE() << "voxel " << got.lattice().coord(q) << " at LPS " << w << " is not on a voxel of the reference";
            continue;
        }
        const PointIndex i = ref.lattice().index(r);
        hit[std::size_t(i)] = 1;
        if (got[q] != ref[i] && !wrong++)
            ADD_FAILURE() << "voxel " << got.lattice().coord(q) << " holds " << +got[q] << ", the reference " << +ref[i];
    }
    EXPECT_EQ(misplaced, 0u);
    EXPECT_EQ(wrong, 0u);
    std::size_t covered = 0;
    for (char h : hit) covered += h != 0;
    EXPECT_EQ(covered, ref.size()) << "not one to one";
}

// Rotation by `deg` degrees about the (normalised) axis a: an oblique, proper direction matrix.
inline Mat3d rotation(Vec3d a, double deg) {
    a = a / norm(a);
    const double t = deg * std::acos(-1.0) / 180.0, c = std::cos(t), s = std::sin(t), C = 1 - c;
    return {c + a.x * a.x * C,       a.x * a.y * C - a.z * s, a.x * a.z * C + a.y * s,
            a.y * a.x * C + a.z * s, c + a.y * a.y * C,       a.y * a.z * C - a.x * s,
            a.z * a.x * C - a.y * s, a.z * a.y * C + a.x * s, c + a.z * a.z * C};
}

// A fresh scratch folder per test (named after `prefix` and the test), removed afterwards unless
// LIVESET_KEEP is set; fails the test up front when minc-tools are missing.
class MincFolderTest : public ::testing::Test {
protected:
    explicit MincFolderTest(std::string prefix) : prefix_(std::move(prefix)) {}
    void SetUp() override {
        const std::string missing = missing_minc_tools();
        ASSERT_TRUE(missing.empty()) << missing;
        dir_ = scratch_dir(prefix_ + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    }
    void TearDown() override {
        std::error_code ec;
        if (!std::getenv("LIVESET_KEEP")) std::filesystem::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string prefix_;
    std::filesystem::path dir_;
};

}  // namespace liveset::testing
