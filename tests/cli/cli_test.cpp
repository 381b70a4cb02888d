// The `liveset` command line as a user meets it: --help/--version, a small experiment with a JSON
// report, and bad flags/values rejected with one clear line on stderr and a non-zero exit.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_run.hpp"
#include "scratch_dir.hpp"

using liveset::testing::lines;
using liveset::testing::run_cli;
using liveset::testing::slurp;
using Result = liveset::testing::CliResult;

TEST(Cli, VersionAndHelp) {
    const Result v = run_cli("--version");
    EXPECT_EQ(v.rc, 0);
    EXPECT_NE(v.out.find("liveset "), std::string::npos);
    const Result h = run_cli("--help");
    EXPECT_EQ(h.rc, 0);
    EXPECT_NE(h.out.find("demo"), std::string::npos);
    EXPECT_NE(h.out.find("segment"), std::string::npos);
    EXPECT_NE(h.out.find("flow"), std::string::npos);
    for (const char* sub : {"demo", "flow", "segment", "mesh", "eval", "phantom", "repair"}) {
        const Result s = run_cli(std::string(sub) + " --help");
        EXPECT_EQ(s.rc, 0) << sub;
        EXPECT_NE(s.out.find("--json"), std::string::npos) << sub;
    }
}

TEST(Cli, FlowReportsAVanishingBoxAsJson) {
    const Result r = run_cli("--threads 2 flow --lattice 24 --box 10 --json --check-every 5");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.out.find("\"vanished\":true"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\"invariants_ok\":true"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("\"volume_monotone\":true"), std::string::npos) << r.out;
    EXPECT_EQ(lines(r.out), 1);
}

TEST(Cli, FlowWritesItsCsvAtomically) {
    const auto csv = liveset::testing::scratch_dir("cli_flow") / "flow.csv";
    const Result r = run_cli("flow --lattice 20 --box 8 --quiet --csv " + csv.string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::string text = slurp(csv);
    EXPECT_EQ(text.rfind("step,time,dt,zero_layer,band,changed,ms\n", 0), 0u);
    EXPECT_GT(lines(text), 5);
    EXPECT_FALSE(std::filesystem::exists(csv.string() + ".tmp"));
    std::filesystem::remove(csv);
    const Result bad = run_cli("flow --lattice 20 --box 8 --quiet --csv /nonexistent-dir/x.csv");
    EXPECT_NE(bad.rc, 0);
    EXPECT_EQ(lines(bad.err), 1) << bad.err;
}

TEST(Cli, BadInputGetsOneLineAndNonZeroExit) {
    for (const char* args : {"", "nonsense", "flow --lattice 0", "flow --lattice abc", "flow --box 200",
                             "flow --layers 0", "flow --cfl nan", "flow --cfl 0.9", "flow --steps -3",
                             "--threads -1 flow", "flow --unknown-flag"}) {
        const Result r = run_cli(args);
        EXPECT_NE(r.rc, 0) << args;
        EXPECT_FALSE(r.err.empty()) << args;
        EXPECT_LE(lines(r.err), 2) << args << ": " << r.err;  // CLI11 adds a "Run with --help" hint
        EXPECT_EQ(r.err.find("terminate"), std::string::npos) << args;
    }
}
