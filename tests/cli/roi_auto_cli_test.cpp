// `liveset segment --roi auto --out-roi`: the written ROI is the library's automatic brain mask of
// the (bias-corrected) image, the segmentation stays inside it, the report counts it; bad input is one line.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <algorithm>
#include <random>

#include "analytic_head.hpp"
#include "labels_as.hpp"
#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/brain_mask.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using liveset::testing::lines;
using liveset::testing::run_cli;
using namespace liveset;

namespace {

fs::path work_dir() {
    static const fs::path dir = liveset::testing::scratch_dir("roi_cli");
    return dir;
}

// The analytic head (analytic_head.hpp) as a file, with or without its bridge to the scalp.
fs::path head_image(bool bridge = false) {
    static const fs::path paths[2] = {work_dir() / "head.nii.gz", work_dir() / "bridged_head.nii.gz"};
    static bool written[2] = {false, false};
    if (!written[bridge]) write_image(liveset::testing::analytic_head(bridge), paths[bridge].string());
    written[bridge] = true;
    return paths[bridge];
}

// The warnings of a `--json` report that name the leak.
std::size_t leak_warnings(const nlohmann::json& j) {
    std::size_t n = 0;
    for (const auto& w : j["warnings"]) n += w.get<std::string>().find("outside the automatic brain mask") != std::string::npos;
    return n;
}

}  // namespace

TEST(RoiAutoCli, WritesTheAutomaticBrainMaskAndSegmentsInsideIt) {
    const fs::path roi = work_dir() / "roi.nii.gz", seg = work_dir() / "seg.nii.gz", corrected = work_dir() / "corrected.nii.gz";
    const auto r = run_cli("segment " + head_image().string() + " --roi auto --out-roi " + roi.string() + " --out-corrected " +
                           corrected.string() + " --seed 32,32,32:3 --mu-raw 112 --epsilon-raw 40 --iterations 300 --json --out-mask " +
                           seg.string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const Grid<float> image = read_image(corrected.string());  // the mask is found again after N4
    BrainMaskReport expected;
    const Grid<std::uint8_t> library = auto_brain_mask(image, {}, &expected);
    const Grid<std::uint8_t> written = read_label_image(roi.string()), mask = read_label_image(seg.string());
    ASSERT_TRUE(written.lattice().same_geometry(image.lattice()));
    EXPECT_TRUE(std::equal(written.values().begin(), written.values().end(), library.values().begin()));
    std::size_t outside = 0, inside = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        outside += mask[static_cast<PointIndex>(i)] != 0 && written[static_cast<PointIndex>(i)] == 0;
        inside += mask[static_cast<PointIndex>(i)] != 0;
    }
    EXPECT_EQ(outside, 0u);
    EXPECT_GT(inside, 1000u);  // the front grew (grey and white matter: the window spans both)
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["roi"]["source"], "auto");
    EXPECT_EQ(j["roi"]["voxels"].get<std::size_t>(), expected.mask_voxels);
    EXPECT_NEAR(j["roi"]["volume_mm3"].get<double>(), expected.mask_volume_mm3, 1e-6);
    EXPECT_FALSE(j["roi"]["auto"]["skull_stripped"].get<bool>());
    EXPECT_EQ(j["roi"]["auto"]["background_noise"].get<double>(), expected.background_noise);
    EXPECT_EQ(j["roi"]["auto"]["head_threshold"].get<double>(), expected.head_threshold);
    EXPECT_EQ(j["outputs"]["roi"], roi.string());
}

// A NIfTI without orientation (qform and sform codes 0, as an Analyze file) reaches the automatic
// brain mask as such: the head's top is found from the head (BrainMask.AHeaderWithoutOrientation…),
// and the report says so; an oriented header is followed.
TEST(RoiAutoCli, AHeaderWithoutOrientationHasItsTopFoundFromTheHead) {
    const fs::path plain = work_dir() / "unoriented.nii";
    write_image(read_image(head_image().string()), plain.string());
    const auto superior = [](const fs::path& image) {
        const auto r = run_cli("segment " + image.string() + " --roi auto --seed 32,32,32:3 --iterations 1 --json --out-mask " +
                               (work_dir() / "unoriented_seg.nii.gz").string());
        EXPECT_EQ(r.rc, 0) << r.err;
        return r.rc == 0 ? nlohmann::json::parse(r.out)["roi"]["auto"]["superior"].get<std::string>() : std::string();
    };
    EXPECT_EQ(superior(plain), "header");
    {
        std::fstream f(plain, std::ios::in | std::ios::out | std::ios::binary);
        const std::int16_t zero = 0;
        f.seekp(252);
        f.write(reinterpret_cast<const char*>(&zero), 2);  // qform_code
        f.write(reinterpret_cast<const char*>(&zero), 2);  // sform_code
    }
    EXPECT_EQ(superior(plain), "from the head");
}

TEST(RoiAutoCli, BadInputIsOneLineAndWritesNothing) {
    const fs::path flat = work_dir() / "flat.nii.gz", noise = work_dir() / "noise.nii.gz";
    write_image(Grid<float>(Lattice({32, 32, 32}), 7.0f), flat.string());
    Grid<float> n(Lattice({32, 32, 32}));
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 100.0f);
    for (float& v : n.values()) v = u(rng);
    write_image(n, noise.string());
    const fs::path out = work_dir() / "never.nii.gz", roi = work_dir() / "never_roi.nii.gz";
    const std::string o = " --seed 5,5,5 --mu-raw 50 --epsilon-raw 5 --out-mask " + out.string();
    struct Case {
        std::string args, phrase;
    };
    for (const Case& c : std::vector<Case>{{"segment " + flat.string() + " --roi auto --out-roi " + roi.string() + o, "constant"},
                                           {"segment " + noise.string() + " --roi auto --out-roi " + roi.string() + o, "no head"},
                                           {"segment " + head_image().string() + " --roi none --out-roi " + roi.string() + o, "--out-roi needs a ROI"},
                                           {"segment " + noise.string() + " --out-roi " + roi.string() + o, "no ROI to write"},
                                           // (5, 5, 5) is air: outside the brain mask asked for
                                           {"segment " + head_image().string() + " --roi auto" + o,
                                            "every seed lies outside the automatic brain mask (--roi auto), the first at voxel (5, 5, 5)"}}) {
        const auto r = run_cli(c.args);
        EXPECT_NE(r.rc, 0) << c.args;
        EXPECT_EQ(lines(r.err), 1) << r.err;
        EXPECT_NE(r.err.find(c.phrase), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
        EXPECT_FALSE(fs::exists(roi));
    }
}

// A ROI file is a mask by its real values, non-zero inside (README): a MINC byte mask with real
// range 0..1 holds 1/255 inside, a resampled one fractions. The same region given as 0/1 labels, as
// 0/(1/255) reals and as 0/0.37 reals segments the same voxels; a NaN in it is one line, nothing written.
TEST(RoiAutoCli, AMaskIsItsNonZeroRealValues) {
    const Grid<float> image = read_image(head_image().string());
    Grid<std::uint8_t> labels(image.lattice(), 0);
    Grid<float> scaled(image.lattice(), 0.0f), fraction(image.lattice(), 0.0f);
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x)
                if (1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5}) < 24) labels({x, y, z}) = 1, scaled({x, y, z}) = 1.0f / 255, fraction({x, y, z}) = 0.37f;
    write_label_image(labels, (work_dir() / "roi_labels.nii.gz").string());
    write_image(scaled, (work_dir() / "roi_scaled.nii.gz").string());
    write_image(fraction, (work_dir() / "roi_fraction.nii.gz").string());
    std::vector<Grid<std::uint8_t>> segs;
    for (const char* name : {"roi_labels", "roi_scaled", "roi_fraction"}) {
        const fs::path seg = work_dir() / (std::string(name) + "_seg.nii.gz");
        const auto r = run_cli("--threads 1 segment " + head_image().string() + " --roi " + (work_dir() / (std::string(name) + ".nii.gz")).string() +
                               " --seed 32,32,32:3 --mu-raw 112 --epsilon-raw 40 --iterations 200 --quiet --out-mask " + seg.string());
        ASSERT_EQ(r.rc, 0) << name << ": " << r.err;
        segs.push_back(read_label_image(seg.string()));
    }
    std::size_t inside = 0, outside_roi = 0;
    for (PointIndex i = 0; i < labels.size(); ++i) inside += segs[0][i] != 0, outside_roi += segs[0][i] && !labels[i];
    EXPECT_GT(inside, 1000u);
    EXPECT_EQ(outside_roi, 0u);
    for (int k : {1, 2}) {
        std::size_t differ = 0;
        for (PointIndex i = 0; i < labels.size(); ++i) differ += segs[k][i] != segs[0][i];
        EXPECT_EQ(differ, 0u) << k;
    }

    scaled[0] = std::nanf("");
    write_image(scaled, (work_dir() / "roi_nan.nii.gz").string());
    const fs::path out = work_dir() / "nan_seg.nii.gz";
    const auto r = run_cli("segment " + head_image().string() + " --roi " + (work_dir() / "roi_nan.nii.gz").string() +
                           " --seed 32,32,32:3 --iterations 5 --quiet --out-mask " + out.string());
    EXPECT_NE(r.rc, 0);
    EXPECT_EQ(lines(r.err), 1) << r.err;
    EXPECT_FALSE(fs::exists(out));
}

// With --roi none, a segmentation of which more than 5 % lies outside the automatic brain mask (the
// front leaked into the scalp) is warned about, with the count against the library's mask; none
// when it stays inside, none with --roi auto.
TEST(RoiAutoCli, WithRoiNoneALeakOutOfTheBrainIsWarnedAbout) {
    const fs::path seg = work_dir() / "leak.nii.gz";
    const std::string o = " --seed 32,32,32:3 --mu-raw 130 --epsilon-raw 40 --iterations 400 --no-bias-correct --json --out-mask " + seg.string();
    const auto leaked = run_cli("segment " + head_image(true).string() + " --roi none" + o);
    ASSERT_EQ(leaked.rc, 0) << leaked.err;
    const nlohmann::json j = nlohmann::json::parse(leaked.out);
    ASSERT_EQ(leak_warnings(j), 1u) << j["warnings"].dump();
    const Grid<std::uint8_t> brain = auto_brain_mask(read_image(head_image(true).string()));
    const Grid<std::uint8_t> mask = read_label_image(seg.string());
    std::size_t outside = 0, inside = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        inside += mask[static_cast<PointIndex>(i)] != 0;
        outside += mask[static_cast<PointIndex>(i)] != 0 && brain[static_cast<PointIndex>(i)] == 0;
    }
    EXPECT_GT(static_cast<double>(outside), 0.05 * static_cast<double>(inside));
    std::string counts = std::to_string(outside) + " of " + std::to_string(inside);
    EXPECT_NE(j["warnings"].dump().find(counts), std::string::npos) << j["warnings"].dump() << " expected " << counts;
    for (const std::string& args : {"segment " + head_image().string() + " --roi none" + o, "segment " + head_image(true).string() + " --roi auto" + o}) {
        const auto r = run_cli(args);
        ASSERT_EQ(r.rc, 0) << r.err;
        EXPECT_EQ(leak_warnings(nlohmann::json::parse(r.out)), 0u) << args << ": " << r.out;
    }
}

// Without --roi, a full head is segmented in its automatic brain mask: the same voxels as --roi auto
// (where --roi none leaks along the bridge), the report's ROI marked as the default; a skull-stripped
// brain (no scalp to leak into) gets no ROI: the same voxels as --roi none.
TEST(RoiAutoCli, AFullHeadIsSegmentedInItsBrainMaskByDefault) {
    const std::string o = " --seed 32,32,32:3 --mu-raw 130 --epsilon-raw 40 --iterations 400 --no-bias-correct --json --out-mask ";
    const auto run = [&](const fs::path& image, const std::string& roi, const std::string& name) {
        const fs::path seg = work_dir() / (name + ".nii.gz");
        const auto r = run_cli("--threads 2 segment " + image.string() + roi + o + seg.string());
        EXPECT_EQ(r.rc, 0) << r.err;
        return std::pair{read_label_image(seg.string()), nlohmann::json::parse(r.out.empty() ? "{}" : r.out)};
    };
    const auto differ = [](const Grid<std::uint8_t>& a, const Grid<std::uint8_t>& b) {
        std::size_t n = 0;
        for (PointIndex i = 0; i < a.size(); ++i) n += a[i] != b[i];
        return n;
    };
    const auto [by_default, jd] = run(head_image(true), "", "default_head");
    const auto [asked, ja] = run(head_image(true), " --roi auto", "auto_head");
    const auto [none, jn] = run(head_image(true), " --roi none", "none_head");
    EXPECT_EQ(differ(by_default, asked), 0u);
    EXPECT_GT(differ(by_default, none), 1000u);  // the leak along the bridge
    EXPECT_EQ(jd["roi"]["source"], "auto");
    EXPECT_TRUE(jd["roi"]["default"].get<bool>());
    EXPECT_FALSE(ja["roi"]["default"].get<bool>());
    EXPECT_EQ(jd["roi"]["voxels"], ja["roi"]["voxels"]);
    EXPECT_FALSE(jn.contains("roi"));
    // A seed in the air beside one in the brain: left out with a warning naming --roi none (the
    // same voxels as without it). Alone, it asks for something else than the brain: the default ROI
    // is dropped, with a warning, and the run is --roi none's voxel for voxel (with --roi auto it is
    // an error: BadInputIsOneLineAndWritesNothing).
    const auto [with_air, jw] = run(head_image(true), " --seed 2,2,2", "air_seed_head");
    EXPECT_EQ(differ(with_air, by_default), 0u);
    std::size_t said = 0;
    for (const auto& w : jw["warnings"])
        said += w.get<std::string>() == "the seed at voxel (2, 2, 2) lies outside the automatic brain mask (the default ROI of a head): it is "
                                        "left out; pass --roi none to segment outside the brain";
    EXPECT_EQ(said, 1u) << jw["warnings"].dump();
    const std::string air_only = " --seed 2,2,2 --mu-raw 8 --epsilon-raw 6 --iterations 50 --no-bias-correct --json --out-mask ";
    const fs::path a1 = work_dir() / "air_default.nii.gz", a2 = work_dir() / "air_none.nii.gz";
    const auto r1 = run_cli("--threads 2 segment " + head_image(true).string() + air_only + a1.string());
    const auto r2 = run_cli("--threads 2 segment " + head_image(true).string() + " --roi none" + air_only + a2.string());
    ASSERT_EQ(r1.rc, 0) << r1.err;
    ASSERT_EQ(r2.rc, 0) << r2.err;
    EXPECT_EQ(differ(read_label_image(a1.string()), read_label_image(a2.string())), 0u);
    const nlohmann::json j1 = nlohmann::json::parse(r1.out);
    EXPECT_FALSE(j1.contains("roi"));
    EXPECT_NE(j1["warnings"].dump().find("every seed lies outside the automatic brain mask (a T1 brain's), the first at voxel (2, 2, 2): the "
                                         "whole image is segmented, as with --roi none"), std::string::npos) << j1["warnings"].dump();
    EXPECT_EQ(j1["warnings"].dump().find("may have leaked"), std::string::npos);  // the whole image was their choice: no advice
    // More than half of the seeds outside (two in the air, one in the brain: as the seeds on a T2,
    // whose mask, looked for as a T1 brain's, is wrong) give the default up too: --roi none's run.
    const auto [two_air, j2a] = run(head_image(true), " --seed 2,2,2 --seed 61,61,61", "two_air_seeds_head");
    const auto [two_air_none, j2n] = run(head_image(true), " --roi none --seed 2,2,2 --seed 61,61,61", "two_air_seeds_none");
    EXPECT_EQ(differ(two_air, two_air_none), 0u);
    EXPECT_FALSE(j2a.contains("roi"));
    EXPECT_NE(j2a["warnings"].dump().find("2 of the 3 seeds lie outside the automatic brain mask (a T1 brain's), the first at voxel (2, 2, 2): "
                                          "the whole image is segmented, as with --roi none"),
              std::string::npos)
        << j2a["warnings"].dump();
    // An initial mask: in the brain (a WM ball) the default ROI stays; in the scalp it is given up
    // as the seeds in the air were (the run is --roi none's).
    const Grid<float> head = read_image(head_image(true).string());
    for (const bool scalp : {false, true}) {
        Grid<std::uint8_t> init(head.lattice(), 0);
        for (int z = 0; z < 64; ++z)
            for (int y = 0; y < 64; ++y)
                for (int x = 0; x < 64; ++x) {
                    const double r = 1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5});
                    init({x, y, z}) = scalp ? (r > 36 && r < 41 && z > 40) : r < 9;
                }
        const std::string name = scalp ? "init_scalp" : "init_wm", path = (work_dir() / (name + ".nii.gz")).string();
        write_label_image(init, path);
        const std::string start = " --init-mask " + path + " --mu-raw 130 --epsilon-raw 40 --iterations 30 --no-bias-correct --json --out-mask ";
        const auto d = run_cli("--threads 2 segment " + head_image(true).string() + start + (work_dir() / (name + "_d.nii.gz")).string());
        const auto n = run_cli("--threads 2 segment " + head_image(true).string() + " --roi none" + start + (work_dir() / (name + "_n.nii.gz")).string());
        ASSERT_EQ(d.rc, 0) << d.err;
        ASSERT_EQ(n.rc, 0) << n.err;
        const nlohmann::json jd2 = nlohmann::json::parse(d.out);
        EXPECT_EQ(jd2.contains("roi"), !scalp) << name;
        EXPECT_EQ(jd2["warnings"].dump().find("of the initial mask lies outside the automatic brain mask") != std::string::npos, scalp) << name;
        if (scalp) {
            EXPECT_EQ(differ(read_label_image((work_dir() / (name + "_d.nii.gz")).string()), read_label_image((work_dir() / (name + "_n.nii.gz")).string())), 0u);
        }
    }

    Grid<float> stripped = liveset::testing::analytic_head(false);  // brain and CSF only, air around
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x)
                if (1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5}) >= 29) stripped({x, y, z}) = 0.0f;
    const fs::path path = work_dir() / "stripped.nii.gz";
    write_image(stripped, path.string());
    ASSERT_TRUE(auto_brain_mask(stripped).lattice().same_geometry(stripped.lattice()));  // a brain is found there...
    const auto [s_default, sd] = run(path, "", "default_stripped");
    const auto [s_none, sn] = run(path, " --roi none", "none_stripped");
    EXPECT_FALSE(sd.contains("roi")) << sd.dump();  // ...but not imposed
    EXPECT_EQ(differ(s_default, s_none), 0u);
}

// A skull-stripped brain z-scored inside its mask, the outside left at 0 (nnU-Net-style): 0 lies in
// a grey-matter window, and the cortex reaches the mask's edge in one place. By default the brain is found as a
// skull-stripped one (BrainMask.AMaskedOutsideWithinTheTissueRangeIsTheOutside) and kept as the
// ROI, after N4 too (its correction about the floor makes the outside uneven): the front stays in
// the brain; with --roi none it flows out into the field of view.
TEST(RoiAutoCli, AMaskedOutsideWithinTheTissueRangeIsKeptAsTheDefaultRoi) {
    Grid<float> head = liveset::testing::analytic_head(false);
    Grid<std::uint8_t> brain(head.lattice(), 0);
    double sum = 0, sum2 = 0, n = 0;
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double r = 1.5 * norm(Vec3d{x - 31.5, y - 31.5, z - 31.5});
                if (r >= 29) continue;  // the brain: white and grey matter, CSF
                if (r >= 27 && x >= 40 && std::abs(y - 31.5) < 4 && std::abs(z - 31.5) < 4) head({x, y, z}) = 95.0f;  // cortex to the mask's edge
                brain({x, y, z}) = 1;
                const double v = head({x, y, z});
                sum += v, sum2 += v * v, n += 1;
            }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    for (PointIndex i = 0; i < head.size(); ++i) head[i] = brain[i] != 0 ? static_cast<float>((head[i] - mean) / sd) : 0.0f;
    const fs::path path = work_dir() / "zscored_brain.nii.gz";
    write_image(head, path.string());
    const double gm = (95.0 - mean) / sd, eps = 0.5;  // the window: grey matter and the outside's 0, neither CSF nor white matter
    ASSERT_LT(std::abs(gm), eps);
    ASSERT_GT((130.0 - mean) / sd, gm + eps + 0.4);
    ASSERT_LT((45.0 - mean) / sd, gm - eps - 0.4);
    const std::string o = " --seed 49,32,32:2 --mu-raw " + std::to_string(gm) + " --epsilon-raw " + std::to_string(eps) +
                          " --iterations 200 --json --out-mask ";
    const auto outside = [&](const std::string& roi, const std::string& name, nlohmann::json& j) {
        const fs::path seg = work_dir() / (name + ".nii.gz");
        const auto r = run_cli("--threads 2 segment " + path.string() + roi + o + seg.string());
        EXPECT_EQ(r.rc, 0) << r.err;
        if (r.rc != 0) return std::size_t{0};
        j = nlohmann::json::parse(r.out);
        const Grid<std::uint8_t> mask = read_label_image(seg.string());
        std::size_t out = 0;
        for (PointIndex i = 0; i < mask.size(); ++i) out += mask[i] != 0 && brain[i] == 0;
        return out;
    };
    nlohmann::json jd, jn;
    EXPECT_EQ(outside("", "zscored_default", jd), 0u);
    EXPECT_GT(outside(" --roi none", "zscored_none", jn), 1000u);
    ASSERT_TRUE(jd.contains("roi")) << jd.dump();
    EXPECT_TRUE(jd["roi"]["default"].get<bool>());
    EXPECT_TRUE(jd["roi"]["auto"]["skull_stripped"].get<bool>());
    EXPECT_EQ(jd["roi"]["auto"]["mid_range_fill"].get<double>(), 0.0);
    EXPECT_NEAR(jd["bias_correction"]["offset"].get<double>(), *std::min_element(head.values().begin(), head.values().end()), 0.5);
}

// The analytic head under Rician noise σ 14 (its air a Rayleigh of mode 14): the report gives the
// air's noise and the head threshold it raised, in the JSON (as the library's report of the
// corrected image, where the mask is found again in the head found first) and in the summary line.
TEST(RoiAutoCli, NoisyAirIsMeasuredAndReported) {
    Grid<float> head = liveset::testing::analytic_head(false);
    std::mt19937 rng(14);
    std::normal_distribution<double> noise(0.0, 14.0);
    for (float& v : head.values()) v = static_cast<float>(std::hypot(v + noise(rng), noise(rng)));
    const fs::path image = work_dir() / "noisy_head.nii.gz";
    write_image(head, image.string());
    BrainMaskReport first;
    BrainMaskHead first_head;
    auto_brain_mask(read_image(image.string()), {}, &first, &first_head);
    EXPECT_NEAR(first.background_noise, 14.0, 1.0);
    EXPECT_GT(first.head_threshold, first.background_threshold);
    const fs::path corrected = work_dir() / "noisy_corrected.nii.gz";
    const std::string args = "segment " + image.string() + " --roi auto --seed 32,32,32:3 --mu-raw 112 --epsilon-raw 40 --iterations 30 --out-mask " +
                             (work_dir() / "noisy_seg.nii.gz").string() + " --out-corrected " + corrected.string();
    const auto r = run_cli(args + " --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    BrainMaskReport expected;
    auto_brain_mask(read_image(corrected.string()), {}, &expected, &first_head);
    EXPECT_GT(expected.background_noise, 0.0);
    EXPECT_GT(expected.head_threshold, expected.background_threshold);
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["roi"]["auto"]["background_noise"].get<double>(), expected.background_noise);
    EXPECT_EQ(j["roi"]["auto"]["head_threshold"].get<double>(), expected.head_threshold);
    EXPECT_EQ(j["roi"]["voxels"].get<std::size_t>(), expected.mask_voxels);
    const auto text = run_cli(args);
    ASSERT_EQ(text.rc, 0) << text.err;
    char line[96];
    std::snprintf(line, sizeof line, "noisy air σ %.1f: head threshold %.1f", expected.background_noise, expected.head_threshold);
    EXPECT_NE(text.out.find(line), std::string::npos) << text.out;
}

// A strong bias field drags the first brain mask's tissue window off: BrainWeb times a ramp of
// 0.63..1.6 along z (a receive coil's) gives a first mask (the library's on the image as read) well off the
// shipped brain mask. With N4 (the default) the mask is found again on the corrected image: the
// written ROI is the library's mask of the corrected image in the head found first, close to the
// shipped mask, and N4's report counts both masks.
TEST(RoiAutoCli, AStrongBiasFieldIsCorrectedBeforeTheMaskIsFoundAgain) {
    const fs::path data = fs::path(LIVESET_DATA_DIR) / "brainweb";
    Grid<float> t1 = read_image((data / "t1.mha").string());
    const Vec3i n = t1.lattice().dims();
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const double u = 2.0 * z / (n.z - 1.0) - 1.0;  // -1..1 from the neck to the vertex
                t1({x, y, z}) *= static_cast<float>(std::exp(std::log(1.6) * u));
            }
    const fs::path image = work_dir() / "biased_brainweb.nii", roi = work_dir() / "biased_roi.nii",
                   corrected = work_dir() / "biased_corrected.nii";
    write_image(t1, image.string());
    const auto r = run_cli("segment " + image.string() + " --roi auto --out-roi " + roi.string() + " --out-corrected " + corrected.string() +
                           " --seed 35,83,113 --iterations 1 --json --out-mask " + (work_dir() / "biased_seg.nii").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const Grid<std::uint8_t> shipped = read_label_image((data / "brain_mask.nii.gz").string());
    const auto dice = [&](const Grid<std::uint8_t>& m) {
        std::size_t a = 0, b = 0, both = 0;
        for (std::size_t i = 0; i < m.size(); ++i) {
            const auto p = static_cast<PointIndex>(i);
            a += m[p] != 0, b += shipped[p] != 0, both += m[p] != 0 && shipped[p] != 0;
        }
        return 2.0 * static_cast<double>(both) / static_cast<double>(a + b);
    };
    BrainMaskReport first_report, again_report;
    BrainMaskHead head;
    const Grid<std::uint8_t> first = auto_brain_mask(read_image(image.string()), {}, &first_report, &head);
    const Grid<std::uint8_t> again = auto_brain_mask(read_image(corrected.string()), {}, &again_report, &head);
    const Grid<std::uint8_t> written = read_label_image(roi.string());
    EXPECT_TRUE(std::equal(written.values().begin(), written.values().end(), again.values().begin()));
    std::printf("brain mask Dice: first %.4f, found again after N4 %.4f\n", dice(first), dice(written));
    EXPECT_LT(dice(first), 0.93);
    EXPECT_GT(dice(written), 0.94);
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["bias_correction"]["mask"], "roi");
    EXPECT_EQ(j["bias_correction"]["mask_voxels"].get<std::size_t>(), first_report.mask_voxels);
    EXPECT_EQ(j["bias_correction"]["brain_mask_after_voxels"].get<std::size_t>(), again_report.mask_voxels);
    EXPECT_EQ(j["roi"]["voxels"].get<std::size_t>(), again_report.mask_voxels);
    EXPECT_EQ(j["roi"]["auto"]["tissue_low"].get<double>(), again_report.tissue_low);
}

// A PD of low grey-white contrast (BrainWeb's labels: CSF 185, GM 162, WM 145, blurred 0.7 mm, noise
// σ 4): N4, fitted in its first brain mask, takes part of that contrast for a field (grey matter lies
// outside white matter), and the mask found again on the corrected image read the head as a T1 and
// took all of it for a stripped brain (GM Dice 0.49 by default). A second look that reads the head
// otherwise than the first is not kept: the written ROI is the first look's, and N4's report counts
// no mask found again.
TEST(RoiAutoCli, ASecondLookThatReadsTheHeadOtherwiseIsNotKept) {
    const Grid<std::uint8_t> labels = read_label_image((fs::path(LIVESET_DATA_DIR) / "brainweb" / "labels_crisp.nii.gz").string());
    const Grid<float> pd = liveset::testing::labels_as(labels, {0, 185, 162, 145, 165, 100, 120, 25, 165, 120});
    const fs::path image = work_dir() / "pd_low_contrast.nii", roi = work_dir() / "pd_roi.nii", corrected = work_dir() / "pd_corrected.nii";
    write_image(pd, image.string());
    const auto r = run_cli("segment " + image.string() + " --roi auto --out-roi " + roi.string() + " --out-corrected " + corrected.string() +
                           " --seed 35,83,113 --iterations 1 --json --out-mask " + (work_dir() / "pd_seg.nii").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    BrainMaskReport first_report, again_report;
    BrainMaskHead head;
    const Grid<std::uint8_t> first = auto_brain_mask(read_image(image.string()), {}, &first_report, &head);
    auto_brain_mask(read_image(corrected.string()), {}, &again_report, &head);
    std::printf("first look: %s, stripped %d, %zu voxels; on the corrected image: %s, stripped %d, %zu voxels\n",
                to_string(first_report.contrast), first_report.skull_stripped, first_report.mask_voxels, to_string(again_report.contrast),
                again_report.skull_stripped, again_report.mask_voxels);
    EXPECT_EQ(first_report.contrast, TissueContrast::kGreyBrighter);
    EXPECT_FALSE(first_report.skull_stripped);
    EXPECT_TRUE(again_report.contrast != first_report.contrast || again_report.skull_stripped);  // the second look misled
    const Grid<std::uint8_t> written = read_label_image(roi.string());
    EXPECT_TRUE(std::equal(written.values().begin(), written.values().end(), first.values().begin()));
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_FALSE(j["bias_correction"].contains("brain_mask_after_voxels"));
    EXPECT_EQ(j["roi"]["voxels"].get<std::size_t>(), first_report.mask_voxels);
    EXPECT_EQ(j["roi"]["auto"]["contrast"], to_string(TissueContrast::kGreyBrighter));
}

// Noise that hides a tissue (window.cpp): BrainWeb under Rician noise σ 18, bias-corrected (the
// default). With `--roi auto` the region is known to be a whole brain, so the model is fitted on
// the blurred image when three classes overlap on the image: three classes, the blur reported,
// the seed voting for grey matter (on the blurred image), and its window ending below the white
// matter's mean. Without a ROI the same (the automatic mask is the fit region). The same mask
// given as a file is a whole brain too (session 69: it agrees with the automatic mask of its head,
// roi.whole_brain); before, a region of unknown shape: two classes on the image, GM and WM merged,
// the window past the white matter.
TEST(RoiAutoCli, NoiseThatHidesATissueIsSeenThroughTheBlurInAnAutomaticBrainMask) {
    const fs::path data = fs::path(LIVESET_DATA_DIR) / "brainweb";
    Grid<float> t1 = read_image((data / "t1.mha").string());
    std::mt19937 rng(57);
    std::normal_distribution<double> noise(0.0, 18.0);
    for (float& v : t1.values()) v = static_cast<float>(std::hypot(v + noise(rng), noise(rng)));
    const fs::path image = work_dir() / "rician18.nii", roi = work_dir() / "rician18_roi.nii";
    write_image(t1, image.string());
    const std::string common = " --seed 35,83,113 --iterations 1 --json --out-mask " + (work_dir() / "rician18_seg.nii").string();
    const auto a = run_cli("segment " + image.string() + " --roi auto --out-roi " + roi.string() + common);
    ASSERT_EQ(a.rc, 0) << a.err;
    const nlohmann::json j = nlohmann::json::parse(a.out);
    ASSERT_EQ(j["tissue_model"]["classes"].size(), 3u) << j["tissue_model"].dump();
    EXPECT_EQ(j["tissue_model"]["fitted_smooth_mm"].get<double>(), 0.5);
    EXPECT_EQ(j["smooth_mm"].get<double>(), 0.5);
    const double wm = j["tissue_model"]["classes"][2]["mean"].get<double>(), gm = j["tissue_model"]["classes"][1]["mean"].get<double>();
    EXPECT_GT(j["window"]["upper_raw"].get<double>(), gm);
    EXPECT_LT(j["window"]["upper_raw"].get<double>(), wm);
    EXPECT_NE(j["warnings"].dump().find("noise hid a tissue"), std::string::npos) << j["warnings"].dump();
    EXPECT_EQ(j["tissue_model"]["seed_class"]["name"], "GM");
    EXPECT_GE(j["tissue_model"]["seed_class"]["share"].get<double>(), 0.7);
    const auto none = run_cli("segment " + image.string() + common);
    ASSERT_EQ(none.rc, 0) << none.err;
    const nlohmann::json n = nlohmann::json::parse(none.out);
    EXPECT_EQ(n["tissue_model"]["classes"].size(), 3u) << n["tissue_model"].dump();
    EXPECT_EQ(n["tissue_model"]["fitted_smooth_mm"].get<double>(), 0.5);
    const auto b = run_cli("segment " + image.string() + " --roi " + roi.string() + common);
    ASSERT_EQ(b.rc, 0) << b.err;
    const nlohmann::json k = nlohmann::json::parse(b.out);
    EXPECT_EQ(k["roi"]["whole_brain"], true);
    EXPECT_EQ(k["tissue_model"]["classes"].size(), 3u) << k["tissue_model"].dump();
    EXPECT_TRUE(k["tissue_model"].contains("fitted_smooth_mm"));
    EXPECT_LT(k["window"]["upper_raw"].get<double>(), wm);
}

// Where the default finds a head but no brain in it (NoBrainFound: here the cortex phantom under
// 20 % noise, whose mask is a fragment of under 10 % of it), it segments the whole image as before,
// but says so once, on stderr and in the report; `--roi auto` is an error naming it; an image with
// no head at all (uniform noise) and `--roi none` say nothing of the kind.
TEST(RoiAutoCli, AHeadWhereNoBrainIsFoundIsSaidNotSilentlySegmentedWhole) {
    const fs::path dir = work_dir() / "nobrain";
    const auto ph = run_cli("phantom --out " + dir.string() + " --size 64 --noise 0.2 -q");
    ASSERT_EQ(ph.rc, 0) << ph.err;
    const std::string image = (dir / "t1.nii.gz").string();
    const std::string said = "the default ROI: a head was found but no brain in it (no brain found (the mask holds";
    const std::string o = " --seed 32,32,32 --mu-raw 900 --epsilon-raw 300 --iterations 20 --no-bias-correct --out-mask ";
    const auto count = [&](const std::string& s) {
        std::size_t n = 0;
        for (std::size_t at = s.find(said); at != std::string::npos; at = s.find(said, at + 1)) ++n;
        return n;
    };
    const auto text = run_cli("--threads 2 segment " + image + o + (dir / "a.nii.gz").string());
    EXPECT_EQ(text.rc, 0) << text.err;
    EXPECT_EQ(count(text.err), 1u) << text.err;
    EXPECT_NE(text.err.find("give --roi a brain mask"), std::string::npos) << text.err;
    const auto json = run_cli("--threads 2 segment " + image + o + (dir / "b.nii.gz").string() + " --json");
    ASSERT_EQ(json.rc, 0) << json.err;
    const nlohmann::json j = nlohmann::json::parse(json.out);
    EXPECT_FALSE(j.contains("roi"));
    std::size_t in_report = 0;
    for (const auto& w : j["warnings"]) in_report += count(w.get<std::string>());
    EXPECT_EQ(in_report, 1u) << j["warnings"].dump();
    const auto none = run_cli("--threads 2 segment " + image + " --roi none" + o + (dir / "c.nii.gz").string());
    EXPECT_EQ(none.rc, 0) << none.err;
    EXPECT_EQ(count(none.err), 0u) << none.err;
    const Grid<std::uint8_t> a = read_label_image((dir / "a.nii.gz").string()), c = read_label_image((dir / "c.nii.gz").string());
    EXPECT_TRUE(std::equal(a.values().begin(), a.values().end(), c.values().begin(), c.values().end()));
    const auto asked = run_cli("--threads 2 segment " + image + " --roi auto" + o + (dir / "d.nii.gz").string());
    EXPECT_NE(asked.rc, 0);
    EXPECT_EQ(lines(asked.err), 1) << asked.err;
    EXPECT_NE(asked.err.find("--roi auto: brain mask: no brain found"), std::string::npos) << asked.err;
    Grid<float> n(Lattice({32, 32, 32}));
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 100.0f);
    for (float& v : n.values()) v = u(rng);
    const fs::path noise = dir / "noise.nii.gz";
    write_image(n, noise.string());
    const auto headless = run_cli("--threads 2 segment " + noise.string() + " --seed 5,5,5 --mu-raw 50 --epsilon-raw 5 --iterations 5 "
                                  "--no-bias-correct --out-mask " + (dir / "e.nii.gz").string());
    EXPECT_EQ(headless.rc, 0) << headless.err;
    EXPECT_EQ(headless.err.find("a head was found"), std::string::npos) << headless.err;
}
