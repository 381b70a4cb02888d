// Recovery files: a written state reads back bit for bit; every damaged file (each truncation, a
// flipped byte, a wrong magic or version, bad geometry, NaN φ, a wrong voxel count) is refused
// with a reason (the crash-signal writer is tested with the viewer: tests/render); and a session restored from a recovery file has the surface, seeds and parameters it had.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/session/recovery.hpp"
#include "liveset/session/repair_presets.hpp"
#include "liveset/session/session.hpp"
#include "session/recovery_samples.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;

// Recomputes the trailing checksum after a deliberate edit, so the field checks are reached.
void reseal(std::vector<std::uint8_t>& bytes) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (std::size_t i = 0; i < bytes.size() - 8; ++i) {
        h ^= bytes[i];
        h *= 0x100000001b3ull;
    }
    std::memcpy(bytes.data() + bytes.size() - 8, &h, 8);
}

std::string refusal(const std::vector<std::uint8_t>& bytes) {
    try {
        decode_recovery(bytes.data(), bytes.size());
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "(accepted)";
}

// Byte offsets of the sample's fields (see the format in recovery.hpp).
constexpr std::size_t kPathLength = 24;
std::size_t dims_offset(const RecoveryState& s) { return kPathLength + 4 + s.image.size(); }
std::size_t spacing_offset(const RecoveryState& s) { return dims_offset(s) + 12; }
std::size_t params_offset(const RecoveryState& s) { return spacing_offset(s) + 15 * 8; }
std::size_t roi_offset(const RecoveryState& s) { return params_offset(s) + 5 * 8 + 1 + 4 + 4 + s.marks.seeds.size() * 32; }
std::size_t step_offset(const RecoveryState& s) { return roi_offset(s) + 1 + 8; }
std::size_t coarse_offset(const RecoveryState& s) { return step_offset(s) + 2; }
std::size_t voxels_offset(const RecoveryState& s) { return coarse_offset(s) + 1; }

// The same state in an older layout: `version` 1-5 recorded no coarse start, 1-4 no step, 1-3 no
// ROI, 1 and 2 had no smoothing σ after α.
std::vector<std::uint8_t> older(const RecoveryState& s, std::uint32_t version) {
    std::vector<std::uint8_t> bytes = encode_recovery(s);
    const auto coarse = bytes.begin() + static_cast<std::ptrdiff_t>(coarse_offset(s));
    bytes.erase(coarse, coarse + 1);
    if (version < 5) {
        const auto step = bytes.begin() + static_cast<std::ptrdiff_t>(step_offset(s));
        bytes.erase(step, step + 2);
    }
    if (version < 4) {
        const auto roi = bytes.begin() + static_cast<std::ptrdiff_t>(roi_offset(s));
        bytes.erase(roi, roi + 9);
    }
    if (version < 3) {
        const auto at = bytes.begin() + static_cast<std::ptrdiff_t>(params_offset(s) + 32);
        bytes.erase(at, at + 8);
    }
    std::memcpy(bytes.data() + 8, &version, 4);
    reseal(bytes);
    return bytes;
}

TEST(Recovery, EncodedStateDecodesBitForBit) {
    RecoveryState s = sample_state();
    s.signal = 11;
    const std::vector<std::uint8_t> bytes = encode_recovery(s);
    EXPECT_EQ(bytes.size(), voxels_offset(s) + 8 + s.phi.size() * 5 + 8);
    expect_same(s, decode_recovery(bytes.data(), bytes.size()));
}

// small_v5 is small (version 1) in version 5's layout: σ 0 and "no ROI" inserted, the exact step
// with the rule, the version and checksum rewritten; small_v6 is small_v5 in today's layout, with
// the coarse start off inserted.
TEST(Recovery, TheFuzzingSeedsAreValidFiles) {
    const RecoveryState v6 = read_recovery(fs::path(LIVESET_SOURCE_DIR) / "fuzz/corpus/recovery/small_v6.lsrecovery");
    ASSERT_TRUE(v6.coarse_start.has_value());  // today's version
    EXPECT_EQ(*v6.coarse_start, CoarseStart::kOff);
    const RecoveryState v5 = read_recovery(fs::path(LIVESET_SOURCE_DIR) / "fuzz/corpus/recovery/small_v5.lsrecovery");
    EXPECT_FALSE(v5.coarse_start.has_value());
    RecoveryState v5_as_v6 = v5;
    v5_as_v6.coarse_start = CoarseStart::kOff;
    expect_same(v6, v5_as_v6);
    ASSERT_TRUE(v5.step.has_value());  // version 5: the exact step with the rule
    EXPECT_FALSE(v5.step->sleeping);
    EXPECT_TRUE(v5.step->thin_fronts);
    EXPECT_TRUE(v5.roi_recorded);
    const RecoveryState s = read_recovery(fs::path(LIVESET_SOURCE_DIR) / "fuzz/corpus/recovery/small.lsrecovery");
    EXPECT_EQ(s.phi.lattice().dims(), (Vec3i{4, 3, 2}));
    EXPECT_EQ(s.marks.seeds.size(), 1u);
    EXPECT_EQ(s.marks.iterations, 12);
    EXPECT_FALSE(s.step.has_value());  // version 1
    EXPECT_EQ(v5.phi.lattice().dims(), s.phi.lattice().dims());  // the same state, in today's layout
    EXPECT_EQ(v5.marks.iterations, s.marks.iterations);
    ASSERT_EQ(v5.phi.size(), s.phi.size());
    for (std::size_t i = 0; i < s.phi.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        EXPECT_EQ(std::bit_cast<std::uint32_t>(v5.phi[p]), std::bit_cast<std::uint32_t>(s.phi[p])) << i;
        EXPECT_EQ(v5.status[p], s.status[p]) << i;
    }
}

TEST(Recovery, EveryTruncationAndEveryFlippedByteIsRefused) {
    const RecoveryState s = sample_state();
    const std::vector<std::uint8_t> bytes = encode_recovery(s);
    for (std::size_t n = 0; n < bytes.size(); ++n) {
        const std::vector<std::uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
        ASSERT_NE(refusal(cut), "(accepted)") << "a file cut to " << n << " bytes was accepted";
    }
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        std::vector<std::uint8_t> flipped = bytes;
        flipped[i] ^= 0x10;
        ASSERT_NE(refusal(flipped), "(accepted)") << "byte " << i << " flipped was accepted";
    }
    std::vector<std::uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_NE(refusal(longer), "(accepted)");
}

TEST(Recovery, DamagedFieldsAreRefusedWithTheirReason) {
    const RecoveryState s = sample_state();
    const std::vector<std::uint8_t> good = encode_recovery(s);
    struct Case {
        const char* name;
        std::size_t offset;
        std::vector<std::uint8_t> value;
        const char* phrase;
    };
    auto i32 = [](std::int32_t v) { std::vector<std::uint8_t> b(4); std::memcpy(b.data(), &v, 4); return b; };
    auto u32 = [](std::uint32_t v) { std::vector<std::uint8_t> b(4); std::memcpy(b.data(), &v, 4); return b; };
    auto f64 = [](double v) { std::vector<std::uint8_t> b(8); std::memcpy(b.data(), &v, 8); return b; };
    auto u64 = [](std::uint64_t v) { std::vector<std::uint8_t> b(8); std::memcpy(b.data(), &v, 8); return b; };
    auto f32 = [](float v) { std::vector<std::uint8_t> b(4); std::memcpy(b.data(), &v, 4); return b; };
    const std::vector<Case> cases{
        {"wrong magic", 0, {'N', 'I', 'F', 'T'}, "wrong magic"},
        {"version 7", 8, u32(7), "version 7"},
        {"version 0", 8, u32(0), "version 0"},
        {"path length beyond the file", kPathLength, u32(1000000), "too long"},
        {"zero dimension", dims_offset(s), i32(0), "invalid geometry"},
        {"negative dimension", dims_offset(s) + 4, i32(-5), "invalid geometry"},
        {"negative spacing", spacing_offset(s), f64(-1.0), "invalid geometry"},
        {"NaN spacing", spacing_offset(s) + 8, f64(std::numeric_limits<double>::quiet_NaN()), "non-finite spacing"},
        {"epsilon 0", params_offset(s) + 8, f64(0.0), "invalid parameters"},
        {"alpha 1", params_offset(s) + 24, f64(1.0), "invalid parameters"},
        {"negative smoothing", params_offset(s) + 32, f64(-0.5), "invalid parameters"},
        {"smoothing beyond its cap", params_offset(s) + 32, f64(1e6), "invalid parameters"},
        {"NaN smoothing", params_offset(s) + 32, f64(std::numeric_limits<double>::quiet_NaN()), "parameters"},
        {"flags 7", params_offset(s) + 40, {7}, "invalid flag"},
        {"flags 4", params_offset(s) + 40, {4}, "invalid flag"},
        {"negative iterations", params_offset(s) + 41, i32(-1), "negative iteration"},
        {"four billion seeds", params_offset(s) + 45, u32(0xFFFFFFFFu), "seed count"},
        {"seed radius 0", params_offset(s) + 49 + 24, f64(0.0), "non-positive radius"},
        {"ROI flag 2", roi_offset(s), {2}, "invalid ROI flag"},
        {"a ROI checksum without a ROI", roi_offset(s), {0}, "without a ROI"},
        {"step 2", step_offset(s), {2}, "invalid step"},
        {"thin-front flag 2", step_offset(s) + 1, {2}, "invalid step"},
        {"coarse start 3", coarse_offset(s), {3}, "invalid coarse start"},
        {"voxel count off by one", voxels_offset(s), u64(s.phi.size() + 1), "voxel count"},
        {"NaN in phi", voxels_offset(s) + 8 + 4 * 17, f32(std::numeric_limits<float>::quiet_NaN()), "NaN"},
        {"infinity in phi", voxels_offset(s) + 8, f32(std::numeric_limits<float>::infinity()), "NaN or infinite"},
    };
    for (const Case& c : cases) {
        std::vector<std::uint8_t> bytes = good;
        ASSERT_LE(c.offset + c.value.size(), bytes.size() - 8) << c.name;
        std::copy(c.value.begin(), c.value.end(), bytes.begin() + static_cast<std::ptrdiff_t>(c.offset));
        reseal(bytes);
        EXPECT_NE(refusal(bytes).find(c.phrase), std::string::npos) << c.name << ": " << refusal(bytes);
    }
    std::vector<std::uint8_t> flipped = good;
    flipped[good.size() / 2] ^= 1;
    EXPECT_NE(refusal(flipped).find("checksum"), std::string::npos) << refusal(flipped);
}

TEST(Recovery, VersionOneFilesStillReadWithAManualAlpha) {
    // Version 1's flags byte held window_from_seeds alone; its files read as before, with α as saved.
    const RecoveryState s = sample_state();
    std::vector<std::uint8_t> bytes = older(s, 1);
    bytes[params_offset(s) + 32] = 1;
    reseal(bytes);
    const RecoveryState old = decode_recovery(bytes.data(), bytes.size());
    EXPECT_TRUE(old.marks.window_from_seeds);
    EXPECT_FALSE(old.marks.alpha_automatic);
    EXPECT_EQ(old.marks.params.alpha, s.marks.params.alpha);
    EXPECT_EQ(old.marks.params.smooth_mm, 0.0);  // before the pre-smoothing: none, as they ran
    bytes[params_offset(s) + 32] = 3;  // bit 1 did not exist in version 1
    reseal(bytes);
    EXPECT_NE(refusal(bytes).find("invalid flag"), std::string::npos) << refusal(bytes);
}

TEST(Recovery, VersionTwoFilesReadWithoutSmoothing) {
    const RecoveryState s = sample_state();
    ASSERT_GT(s.marks.params.smooth_mm, 0.0);
    const std::vector<std::uint8_t> bytes = older(s, 2);
    const RecoveryState old = decode_recovery(bytes.data(), bytes.size());
    EXPECT_EQ(old.marks.params.smooth_mm, 0.0);
    RecoveryState expected = s;
    expected.marks.params.smooth_mm = 0.0;
    expected.roi_recorded = false;
    expected.roi_checksum.reset();
    expected.step.reset();
    expected.coarse_start.reset();
    expect_same(old, expected);  // everything else as saved, φ and statuses bit for bit
}

// Version 4 records the session's ROI (its mask_checksum, or none); version 3 recorded nothing, and
// reads as such, so that a restore compares only what was written.
TEST(Recovery, TheROIIsRecordedAndOlderFilesSayTheyRecordedNone) {
    RecoveryState s = sample_state();
    const std::vector<std::uint8_t> v3 = older(s, 3);
    RecoveryState expected = s;
    expected.roi_recorded = false;
    expected.roi_checksum.reset();
    expected.step.reset();
    expected.coarse_start.reset();
    expect_same(decode_recovery(v3.data(), v3.size()), expected);
    s.roi_checksum.reset();
    const std::vector<std::uint8_t> none = encode_recovery(s);
    const RecoveryState back = decode_recovery(none.data(), none.size());
    EXPECT_TRUE(back.roi_recorded);
    EXPECT_FALSE(back.roi_checksum.has_value());
    // The checksum reads a mask's inside/outside only, and tells two masks apart.
    Grid<std::uint8_t> a(Lattice({4, 3, 2}), 0), b = a;
    a[5] = 1;
    b[5] = 255;
    EXPECT_EQ(mask_checksum(a), mask_checksum(b));
    b[6] = 1;
    EXPECT_NE(mask_checksum(a), mask_checksum(b));
    EXPECT_EQ(roi_difference(mask_checksum(a), mask_checksum(a)), "");
    EXPECT_EQ(roi_difference(std::nullopt, std::nullopt), "");
    EXPECT_EQ(roi_difference(mask_checksum(a), mask_checksum(b)), "saved with another ROI");
    EXPECT_EQ(roi_difference(std::nullopt, mask_checksum(a)), "saved without a ROI, opened with one");
    EXPECT_EQ(roi_difference(mask_checksum(a), std::nullopt), "saved with a ROI, opened without one");
}

// Version 5 records the session's step (sleeping or exact, the thin-front rule on or off); version 4
// recorded none, and reads as such (the command line's step continues it), all else as saved. The
// step as the command line builds it: sleeping_step() or StepOptions{}, with the rule or not.
TEST(Recovery, TheStepIsRecordedAndOlderFilesSayTheyRecordedNone) {
    const RecoveryState s = sample_state();
    const std::vector<std::uint8_t> v4 = older(s, 4);
    RecoveryState expected = s;
    expected.step.reset();
    expected.coarse_start.reset();
    expect_same(decode_recovery(v4.data(), v4.size()), expected);
    for (const bool sleeping : {false, true})
        for (const bool thin : {false, true}) {
            RecoveryState t = s;
            t.step = RecordedStep{sleeping, thin};
            const std::vector<std::uint8_t> bytes = encode_recovery(t);
            EXPECT_EQ(bytes[step_offset(t)], sleeping ? 1 : 0);
            EXPECT_EQ(bytes[step_offset(t) + 1], thin ? 1 : 0);
            expect_same(t, decode_recovery(bytes.data(), bytes.size()));
            const StepOptions o = step_options(*t.step);
            EXPECT_EQ(std::string(step_name(o)), sleeping ? "sleeping" : "exact");
            EXPECT_EQ(o.thin_fronts, thin);
            EXPECT_TRUE(recorded_step(o) == *t.step);
        }
    EXPECT_TRUE(recorded_step(segment_step()) == RecordedStep{});  // the default: sleeping, with the rule
    EXPECT_EQ(describe(RecordedStep{false, false}), "--step exact --no-thin-fronts");
    EXPECT_EQ(describe(RecordedStep{}), "--step sleeping --thin-fronts");
}

// Version 6 records the session's coarse start from seeds (auto, on or off); version 5 recorded
// none, and reads as such (the command line's continues it), all else as saved.
TEST(Recovery, TheCoarseStartIsRecordedAndOlderFilesSayTheyRecordedNone) {
    const RecoveryState s = sample_state();
    ASSERT_TRUE(s.coarse_start.has_value());
    const std::vector<std::uint8_t> v5 = older(s, 5);
    RecoveryState expected = s;
    expected.coarse_start.reset();
    expect_same(decode_recovery(v5.data(), v5.size()), expected);
    const std::pair<CoarseStart, std::uint8_t> modes[] = {{CoarseStart::kAuto, 0}, {CoarseStart::kOn, 1}, {CoarseStart::kOff, 2}};
    for (const auto& [mode, byte] : modes) {
        RecoveryState t = s;
        t.coarse_start = mode;
        const std::vector<std::uint8_t> bytes = encode_recovery(t);
        EXPECT_EQ(bytes[coarse_offset(t)], byte) << to_string(mode);
        const RecoveryState back = decode_recovery(bytes.data(), bytes.size());
        ASSERT_TRUE(back.coarse_start.has_value());
        EXPECT_EQ(*back.coarse_start, mode);
        expect_same(t, back);
    }
}

TEST(Recovery, FilesAreWrittenWholeOrNotAtAll) {
    const fs::path dir = fresh_dir("files");
    const RecoveryState s = sample_state();
    const fs::path path = recovery_path(dir, s.image);
    EXPECT_EQ(path.parent_path(), dir);
    EXPECT_EQ(path.extension(), ".lsrecovery");
    EXPECT_NE(recovery_path(dir, "/other/t1.nii.gz"), path) << "two images with one file name share a recovery file";
    EXPECT_NE(recovery_path(dir, s.image, "n4"), path) << "an image and its bias-corrected copy share a recovery file";
    EXPECT_EQ(recovery_path(dir, s.image, "n4").parent_path(), path.parent_path());
    write_recovery(path, s);
    expect_same(s, read_recovery(path));
    EXPECT_FALSE(fs::exists(path.string() + ".part"));
    // Unwritable place: an exception naming the file, nothing left behind.
    const fs::path blocked = dir / "not_a_folder";
    std::ofstream(blocked) << "x";
    EXPECT_THROW(write_recovery(blocked / "r.lsrecovery", s), std::runtime_error);
    // Missing and empty files: one-line refusals naming the file.
    try {
        read_recovery(dir / "missing.lsrecovery");
        ADD_FAILURE() << "a missing file was read";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("missing.lsrecovery"), std::string::npos) << e.what();
    }
    std::ofstream(dir / "empty.lsrecovery");
    EXPECT_THROW(read_recovery(dir / "empty.lsrecovery"), std::runtime_error);
    fs::remove_all(dir);
}

TEST(Recovery, ARestoredSessionHasTheSurfaceSeedsAndParametersItHad) {
    PhantomOptions po;
    po.size = 48;
    const Phantom ph = make_phantom(po);
    SessionOptions o;
    o.repair = demo_repair_options();
    Session a(ph.image, o);
    for (const Vec3i& c : ph.seeds) a.add_seed({c.cast<double>(), 2.0});
    for (int i = 0; i < 40; ++i) a.segment_step();
    a.end_action();

    RecoveryState saved;
    saved.image = "phantom";
    saved.marks = a.marks();
    saved.phi = a.field().phi();
    saved.status = a.field().status();
    const std::vector<std::uint8_t> bytes = encode_recovery(saved);
    const RecoveryState back = decode_recovery(bytes.data(), bytes.size());

    Session b(ph.image, o);
    EXPECT_TRUE(b.load_recovered(back.phi, back.status, back.marks)) << "the saved sparse field was not taken as it is";
    for (std::size_t i = 0; i < a.field().phi().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a.field().phi()[p]), std::bit_cast<std::uint32_t>(b.field().phi()[p])) << i;
        ASSERT_EQ(a.field().status()[p], b.field().status()[p]) << i;
    }
    EXPECT_EQ(b.seeds().size(), a.seeds().size());
    EXPECT_EQ(b.params().mu, a.params().mu);
    EXPECT_EQ(b.params().epsilon, a.params().epsilon);
    EXPECT_EQ(b.segment_status().iterations, 40);
    EXPECT_FALSE(b.can_undo()) << "the history starts afresh from the restored state";
    const Grid<std::uint8_t> ma = a.mask(), mb = b.mask();
    EXPECT_TRUE(std::equal(ma.values().begin(), ma.values().end(), mb.values().begin(), mb.values().end()));
    EXPECT_EQ(canonical_triangles(a.mesher().merged()), canonical_triangles(b.mesher().merged()));
    // The restored session goes on segmenting as the original does.
    for (int i = 0; i < 20; ++i) {
        a.segment_step();
        b.segment_step();
    }
    const Grid<std::uint8_t> ma2 = a.mask(), mb2 = b.mask();
    EXPECT_TRUE(std::equal(ma2.values().begin(), ma2.values().end(), mb2.values().begin(), mb2.values().end()));

    // A status that is no sparse field — a far point marked as zero layer, or a value no layer has
    // (what a crash in the middle of an update leaves): φ's signs are used.
    for (const std::int8_t bad : {std::int8_t{0}, std::int8_t{12}, std::int8_t{-128}}) {
        Grid<std::int8_t> broken = back.status;
        broken[0] = bad;
        Session c(ph.image, o);
        EXPECT_FALSE(c.load_recovered(back.phi, broken, back.marks)) << int(bad);
        const Grid<std::uint8_t> mc = c.mask();
        EXPECT_TRUE(std::equal(ma.values().begin(), ma.values().end(), mc.values().begin(), mc.values().end())) << int(bad);
    }

    SessionMarks outside = back.marks;
    outside.seeds.push_back({{1000.0, 0.0, 0.0}, 2.0});
    EXPECT_THROW(b.load_recovered(back.phi, back.status, outside), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
