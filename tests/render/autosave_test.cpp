// No lost work, end to end through `liveset view --headless`: unsaved work is kept in a recovery
// file at exit and restored (same evaluation) with --recover; saving removes the file; a
// termination signal in the middle of a segmentation writes the state it had; a damaged recovery
// file is reported in one line and replaced, never fatal.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fmt/core.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cli/cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/session/recovery.hpp"
#include "scratch_dir.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;
using testing::CliResult;
using testing::run_cli;

struct Fixture {
    fs::path dir, recovery;
    std::string image, truth, seeds;
};

const Fixture& fixture() {
    static const Fixture f = [] {
        Fixture x;
        x.dir = testing::scratch_dir("autosave_test");
        PhantomOptions o;
        o.size = 64;
        const Phantom ph = make_phantom(o);
        x.image = (x.dir / "t1.nii.gz").string();
        x.truth = (x.dir / "truth.nii.gz").string();
        write_image(ph.image, x.image);
        write_label_image(ph.truth, x.truth);
        for (const Vec3i& s : ph.seeds) x.seeds += fmt::format("{{\"seed\": [{}, {}, {}]}}, ", s.x, s.y, s.z);
        return x;
    }();
    return f;
}

fs::path script(const fs::path& dir, const std::string& name, const std::string& body) {
    const fs::path p = dir / name;
    std::ofstream(p) << body;
    return p;
}

std::vector<fs::path> recovery_files(const fs::path& dir) {
    std::vector<fs::path> r;
    if (fs::exists(dir))
        for (const auto& e : fs::directory_iterator(dir))
            if (e.path().extension() == ".lsrecovery") r.push_back(e.path());
    return r;
}

nlohmann::json first_eval(const std::string& out) {
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line.front() == '{') return nlohmann::json::parse(line)["eval"];
    return nullptr;
}

std::string view(const Fixture& f, const fs::path& rec, const fs::path& s, const std::string& extra = "") {
    return "view " + f.image + " --headless --recovery-dir " + rec.string() + " --script " + s.string() + " " + extra;
}

TEST(Autosave, UnsavedWorkIsKeptAtExitRestoredWithRecoverAndGoneOnceSaved) {
    const Fixture& f = fixture();
    const fs::path rec = f.dir / "rec1";
    fs::remove_all(rec);
    const std::string eval = R"({"eval": {"truth": ")" + f.truth + R"("}})";
    const CliResult first = run_cli(view(f, rec, script(f.dir, "work.json", "[" + f.seeds + R"({"segment": 40}, )" + eval + "]")));
    ASSERT_EQ(first.rc, 0) << first.err;
    EXPECT_NE(first.err.find("kept the unsaved work"), std::string::npos) << first.err;
    const auto files = recovery_files(rec);
    ASSERT_EQ(files.size(), 1u);
    const RecoveryState kept = read_recovery(files[0]);
    EXPECT_EQ(kept.image, f.image);
    EXPECT_EQ(kept.signal, 0);
    EXPECT_EQ(kept.marks.iterations, 40);
    EXPECT_EQ(kept.marks.seeds.size(), 5u);

    // Without --recover: one note, the file stays for a later choice.
    const CliResult ignored = run_cli(view(f, rec, script(f.dir, "idle.json", R"([{"layout": "four"}])")));
    ASSERT_EQ(ignored.rc, 0) << ignored.err;
    EXPECT_NE(ignored.err.find("--recover restores it"), std::string::npos) << ignored.err;
    EXPECT_EQ(recovery_files(rec).size(), 1u);
    // The work was on the N4-corrected image (the default): a session on the raw image has a
    // recovery file of its own and is not offered this one.
    EXPECT_EQ(files[0], recovery_path(rec, f.image, "n4"));
    const CliResult raw = run_cli(view(f, rec, script(f.dir, "idle.json", R"([{"layout": "four"}])"), "--no-bias-correct --recover"));
    ASSERT_EQ(raw.rc, 0) << raw.err;
    EXPECT_EQ(raw.err.find("restored unsaved work"), std::string::npos) << raw.err;
    EXPECT_EQ(raw.err.find("--recover restores it"), std::string::npos) << raw.err;
    EXPECT_EQ(recovery_files(rec).size(), 1u);

    // --recover: the same surface as before the exit; saving the mask then removes the file.
    const fs::path mask = f.dir / "restored_mask.nii.gz";
    const CliResult restored =
        run_cli(view(f, rec, script(f.dir, "save.json", "[" + eval + R"(, {"save_mask": ")" + mask.string() + R"("}])"), "--recover"));
    ASSERT_EQ(restored.rc, 0) << restored.err;
    EXPECT_NE(restored.err.find("restored unsaved work"), std::string::npos) << restored.err;
    const nlohmann::json before = first_eval(first.out), after = first_eval(restored.out);
    ASSERT_FALSE(before.is_null());
    ASSERT_FALSE(after.is_null()) << restored.out;
    EXPECT_EQ(before["dice"], after["dice"]);
    EXPECT_EQ(before["holes"], after["holes"]);
    EXPECT_EQ(before["genus"], after["genus"]);
    EXPECT_EQ(before["jaccard"], after["jaccard"]);
    EXPECT_TRUE(fs::exists(mask));
    EXPECT_TRUE(recovery_files(rec).empty()) << "the work was saved: its recovery file should be gone";
}

// The recovery file records the session's ROI; restoring the work where the ROI differs says so
// (the work is restored: the user chose the ROI), as a continued workspace does.
TEST(Autosave, ARestoreInAnotherROIIsNamed) {
    const Fixture& f = fixture();
    const fs::path rec = f.dir / "rec_roi";
    fs::remove_all(rec);
    const Grid<float> image = read_image(f.image);
    Grid<std::uint8_t> box(image.lattice(), 0);
    for (int k = 4; k < 60; ++k)
        for (int j = 4; j < 60; ++j)
            for (int i = 4; i < 60; ++i) box({i, j, k}) = 1;
    const fs::path roi = f.dir / "box_roi.nii.gz";
    write_label_image(box, roi.string());
    const CliResult first =
        run_cli(view(f, rec, script(f.dir, "work_roi.json", "[" + f.seeds + R"({"segment": 10}])"), "--roi " + roi.string()));
    ASSERT_EQ(first.rc, 0) << first.err;
    const auto files = recovery_files(rec);
    ASSERT_EQ(files.size(), 1u);
    const RecoveryState kept = read_recovery(files[0]);
    EXPECT_TRUE(kept.roi_recorded);
    ASSERT_TRUE(kept.roi_checksum.has_value());
    EXPECT_EQ(*kept.roi_checksum, mask_checksum(box));
    const fs::path idle = script(f.dir, "idle_roi.json", R"([{"layout": "four"}])");
    const CliResult same = run_cli(view(f, rec, idle, "--roi " + roi.string()));
    ASSERT_EQ(same.rc, 0) << same.err;
    EXPECT_NE(same.err.find("--recover restores it"), std::string::npos) << same.err;
    EXPECT_EQ(same.err.find("ROI"), std::string::npos) << same.err;
    const CliResult other = run_cli(view(f, rec, idle, "--recover"));
    ASSERT_EQ(other.rc, 0) << other.err;
    EXPECT_NE(other.err.find("restored unsaved work"), std::string::npos) << other.err;
    EXPECT_NE(other.err.find("saved with a ROI, opened without one"), std::string::npos) << other.err;
}

// The recovery file records the session's step: restored, the work continues with it (here the
// exact step without the thin-front rule, in a viewer opened with the defaults), 30 more steps
// giving what one uninterrupted run of that step gives; where the command line asks for the rule,
// it continues with that, said, and ends elsewhere.
TEST(Autosave, ARestoredWorkContinuesWithItsStep) {
    const Fixture& f = fixture();
    const std::string eval = R"({"eval": {"truth": ")" + f.truth + R"("}})";
    const std::string exact = "--step exact --no-thin-fronts";
    const fs::path once = f.dir / "rec_step_once";
    fs::remove_all(once);
    const CliResult whole =
        run_cli(view(f, once, script(f.dir, "step_whole.json", "[" + f.seeds + R"({"segment": 10}, {"segment": 30}, )" + eval + "]"), exact));
    ASSERT_EQ(whole.rc, 0) << whole.err;
    for (const bool ask_rule : {false, true}) {
        const fs::path rec = f.dir / (ask_rule ? "rec_step_asked" : "rec_step");
        fs::remove_all(rec);
        const CliResult first = run_cli(view(f, rec, script(f.dir, "step_first.json", "[" + f.seeds + R"({"segment": 10}])"), exact));
        ASSERT_EQ(first.rc, 0) << first.err;
        const auto files = recovery_files(rec);
        ASSERT_EQ(files.size(), 1u);
        const RecoveryState kept = read_recovery(files[0]);
        ASSERT_TRUE(kept.step.has_value());
        EXPECT_FALSE(kept.step->sleeping);
        EXPECT_FALSE(kept.step->thin_fronts);
        const CliResult next = run_cli(
            view(f, rec, script(f.dir, "step_next.json", R"([{"segment": 30}, )" + eval + "]"), ask_rule ? "--recover --thin-fronts" : "--recover"));
        ASSERT_EQ(next.rc, 0) << next.err;
        const nlohmann::json want = first_eval(whole.out), got = first_eval(next.out);
        ASSERT_FALSE(want.is_null() || got.is_null()) << next.out;
        if (!ask_rule) {
            EXPECT_NE(next.err.find("continued with its saved --step exact --no-thin-fronts"), std::string::npos) << next.err;
            EXPECT_EQ(want["dice"], got["dice"]);
            EXPECT_EQ(want["genus"], got["genus"]);
            EXPECT_EQ(want["jaccard"], got["jaccard"]);
        } else {
            EXPECT_NE(next.err.find("continued with --step exact --thin-fronts as asked (saved with --step exact --no-thin-fronts)"),
                      std::string::npos)
                << next.err;
            EXPECT_NE(want["jaccard"], got["jaccard"]) << "the rule changed nothing here: the test cannot tell the steps apart";
        }
        // Kept at exit again: with the step it continued with.
        const auto again = recovery_files(rec);
        ASSERT_EQ(again.size(), 1u);
        const RecoveryState after = read_recovery(again[0]);
        ASSERT_TRUE(after.step.has_value());
        EXPECT_FALSE(after.step->sleeping);
        EXPECT_EQ(after.step->thin_fronts, ask_rule);
    }
}

// The recovery file records the session's coarse start: work saved before its first step with
// --coarse-start on (the 1 mm phantom's default, auto, would not start coarse), restored in a viewer
// opened without the flag, runs coarse and ends on the φ of one uninterrupted run with `on`, bit for
// bit, not on the default's; with --coarse-start off asked, it says so and ends on the default's.
TEST(Autosave, ARestoredWorkContinuesWithItsCoarseStart) {
    const Fixture& f = fixture();
    const std::string converge = R"({"segment": "converge", "max": 3000}, {"save_phi": ")";
    auto phi_of = [&](const std::string& name, const fs::path& rec, const std::string& head, const std::string& extra) {
        const std::string out = (f.dir / (name + ".nii.gz")).string();
        const CliResult r = run_cli(view(f, rec, script(f.dir, name + ".json", "[" + head + converge + out + R"("}])"), extra));
        EXPECT_EQ(r.rc, 0) << r.err;
        return std::pair(read_image(out), r.err);
    };
    fs::remove_all(f.dir / "rec_coarse_one");
    fs::remove_all(f.dir / "rec_coarse_plain");
    const auto [one, one_err] = phi_of("coarse_one", f.dir / "rec_coarse_one", f.seeds, "--coarse-start on");
    const auto [plain, plain_err] = phi_of("coarse_plain", f.dir / "rec_coarse_plain", f.seeds, "");
    ASSERT_FALSE(testing::same_bits(one, plain)) << "the coarse start changed nothing here: the test cannot tell them apart";
    for (const bool ask_off : {false, true}) {
        const fs::path rec = f.dir / (ask_off ? "rec_coarse_asked" : "rec_coarse");
        fs::remove_all(rec);
        const CliResult first = run_cli(view(f, rec, script(f.dir, "coarse_first.json", "[" + f.seeds.substr(0, f.seeds.size() - 2) + "]"), "--coarse-start on"));
        ASSERT_EQ(first.rc, 0) << first.err;
        const auto files = recovery_files(rec);
        ASSERT_EQ(files.size(), 1u);
        const RecoveryState kept = read_recovery(files[0]);
        ASSERT_TRUE(kept.coarse_start.has_value());
        EXPECT_EQ(*kept.coarse_start, CoarseStart::kOn);
        EXPECT_EQ(kept.marks.iterations, 0);
        const auto [got, err] = phi_of(ask_off ? "coarse_asked" : "coarse_next", rec, "", ask_off ? "--recover --coarse-start off" : "--recover");
        if (!ask_off) {
            EXPECT_NE(err.find("continued with its saved --coarse-start on"), std::string::npos) << err;
            EXPECT_TRUE(testing::same_bits(got, one));
        } else {
            EXPECT_NE(err.find("continued with --coarse-start off as asked (saved with --coarse-start on)"), std::string::npos) << err;
            EXPECT_TRUE(testing::same_bits(got, plain));
        }
    }
}

TEST(Autosave, ATerminationSignalMidSegmentationWritesTheStateItHad) {
    const Fixture& f = fixture();
    const fs::path rec = f.dir / "rec2";
    fs::remove_all(rec);
    const fs::path s = script(f.dir, "long.json", "[" + f.seeds + R"({"segment": 1000000}])");
    const fs::path err = f.dir / "long.err";
    const std::string err_path = err.string();
    const pid_t pid = ::fork();
    if (pid == 0) {  // only async-signal-safe calls until exec
        const int e = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), n = ::open("/dev/null", O_WRONLY);
        if (e < 0 || n < 0 || ::dup2(e, 2) < 0 || ::dup2(n, 1) < 0) ::_exit(120);
        ::execl(LIVESET_CLI_PATH, LIVESET_CLI_PATH, "view", f.image.c_str(), "--headless", "--recovery-dir", rec.c_str(),
                "--autosave-every", "0", "--script", s.c_str(), static_cast<char*>(nullptr));
        ::_exit(121);
    }
    // --autosave-every 0 writes at every change: the file's appearance says the segmentation runs.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (recovery_files(rec).empty() && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_FALSE(recovery_files(rec).empty()) << "no autosave within 2 minutes";
    // Wait until an autosave shows segmentation steps (a loaded machine may take a while to get
    // past the seeds), then interrupt the run mid-segmentation.
    const auto stepping = [&] {
        for (const fs::path& f : recovery_files(rec)) try {
                if (read_recovery(f).marks.iterations > 0) return true;
            } catch (const std::runtime_error&) {
            }
        return false;
    };
    while (!stepping() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ::kill(pid, SIGTERM);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << WEXITSTATUS(status) << ": " << testing::slurp(err);
    EXPECT_EQ(WTERMSIG(status), SIGTERM);
    const auto files = recovery_files(rec);
    ASSERT_EQ(files.size(), 1u);
    const RecoveryState got = read_recovery(files[0]);
    EXPECT_EQ(got.signal, SIGTERM) << "the file is the last autosave, not the signal's";
    EXPECT_GT(got.marks.iterations, 0);
    EXPECT_EQ(got.marks.seeds.size(), 5u);

    const CliResult restored = run_cli(view(f, rec, script(f.dir, "eval.json", R"([{"eval": {"truth": ")" + f.truth + R"("}}])"), "--recover"));
    ASSERT_EQ(restored.rc, 0) << restored.err;
    EXPECT_NE(restored.err.find("SIGTERM"), std::string::npos) << restored.err;
    const nlohmann::json e = first_eval(restored.out);
    ASSERT_FALSE(e.is_null());
    EXPECT_GT(e["dice"].get<double>(), 0.0);
}

TEST(Autosave, ADamagedRecoveryFileIsReportedAndReplaced) {
    const Fixture& f = fixture();
    const fs::path rec = f.dir / "rec3";
    fs::remove_all(rec);
    fs::create_directories(rec);
    const fs::path file = recovery_path(rec, f.image, "n4");  // the viewer's default: N4 first
    std::ofstream(file) << "LSRECOV1 but nothing after it";
    const CliResult r = run_cli(view(f, rec, script(f.dir, "short.json", "[" + f.seeds + R"({"segment": 5}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("ignoring a damaged recovery file"), std::string::npos) << r.err;
    EXPECT_EQ(read_recovery(file).marks.iterations, 5);

    const CliResult no_dir = run_cli("view " + f.image + " --headless --recover --script " + (f.dir / "short.json").string());
    EXPECT_NE(no_dir.rc, 0);
    EXPECT_NE(no_dir.err.find("--recover needs"), std::string::npos) << no_dir.err;
}

}  // namespace
}  // namespace liveset
