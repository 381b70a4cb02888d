// `liveset bench fig3` as a user runs it: a small Figure 3 experiment writes a well-formed CSV
// (one row per step, cumulative columns never decreasing) and a PNG; bad values and an unwritable
// output directory are refused with one line on stderr and a non-zero exit.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "scratch_dir.hpp"

namespace {

using liveset::testing::lines;
using liveset::testing::run_cli;
using liveset::testing::scratch_dir;
using liveset::testing::slurp;
using Result = liveset::testing::CliResult;

namespace fs = std::filesystem;

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::string cur;
    std::istringstream in(s);
    while (std::getline(in, cur, sep)) parts.push_back(cur);
    return parts;
}

}  // namespace

TEST(BenchCli, Fig3WritesCsvAndPng) {
    const fs::path out = scratch_dir("bench_fig3");
    const Result r = run_cli("--threads 2 bench fig3 --steps 40 --lattice 30 --box 14 --verify-every 10 --out " + out.string());
    ASSERT_EQ(r.rc, 0) << r.err << r.out;
    EXPECT_NE(r.out.find("mesh checks"), std::string::npos) << r.out;

    const std::vector<std::string> rows = split(slurp(out / "fig3.csv"), '\n');
    ASSERT_EQ(rows.size(), 41u);
    // Sizes 50 and 100 cover the 29-cell lattice: both are the naive whole-lattice scan; the band
    // column is named after the lattice (30 points), as the paper names its 100-point lattice x100.
    EXPECT_EQ(rows[0], "step,x3,x5,x10,x20,x25,x50,x100,x30_band");
    std::vector<double> prev(8, 0.0);
    for (std::size_t i = 1; i < rows.size(); ++i) {
        const std::vector<std::string> cells = split(rows[i], ',');
        ASSERT_EQ(cells.size(), 9u) << rows[i];
        EXPECT_EQ(std::stoi(cells[0]), static_cast<int>(i));
        for (std::size_t c = 1; c < cells.size(); ++c) {
            const double v = std::stod(cells[c]);
            EXPECT_GE(v, prev[c - 1]) << "column " << c << " decreases at step " << i;
            prev[c - 1] = v;
        }
    }
    for (double v : prev) EXPECT_GT(v, 0.0);

    const std::string png = slurp(out / "fig3.png");
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_FALSE(fs::exists(out / "fig3.csv.tmp"));
    EXPECT_FALSE(fs::exists(out / "fig3.png.tmp"));
    fs::remove_all(out);
}

TEST(BenchCli, Fig3RefusesBadArgumentsWithOneLine) {
    const fs::path base = scratch_dir("bench_bad");
    const fs::path file = base / "a-file";
    std::ofstream(file) << "not a directory\n";
    const std::string ok_out = " --out " + (base / "out").string();
    for (const std::string& args :
         {std::string("bench fig3 --sizes 2") + ok_out, std::string("bench fig3 --steps -1") + ok_out,
          std::string("bench fig3 --steps 0") + ok_out, std::string("bench fig3 --sizes 5,5") + ok_out,
          std::string("bench fig3 --lattice 20 --box 19") + ok_out,
          "bench fig3 --steps 3 --lattice 12 --box 4 --out " + (file / "sub").string()}) {
        const Result r = run_cli(args);
        EXPECT_NE(r.rc, 0) << args;
        EXPECT_EQ(lines(r.err), 1) << args << ": " << r.err;
        EXPECT_EQ(r.err.find("terminate"), std::string::npos) << args;
    }
    EXPECT_FALSE(fs::exists(base / "out" / "fig3.csv"));
    fs::remove_all(base);
}

// bench soak: a short run on a small phantom passes every invariant and mesh check and logs one
// line per check; a broken input is refused in one line.
TEST(BenchCli, SoakChecksTheLevelSetAndTheMeshesAndLogsMemory) {
    const fs::path dir = scratch_dir("bench_soak");
    ASSERT_EQ(run_cli("phantom --size 48 --quiet --out " + (dir / "ph").string()).rc, 0);
    const std::string common = (dir / "ph" / "truth_gm.nii.gz").string() + " --image " + (dir / "ph" / "t1.nii.gz").string();
    const Result r = run_cli("bench soak " + common + " --iterations 1200 --check-every 400 --json --log " + (dir / "soak.jsonl").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const nlohmann::json s = nlohmann::json::parse(r.out);
    EXPECT_EQ(s["checks"], 3);
    EXPECT_GT(s["rss_peak_mb"].get<double>(), 0.0);
    std::istringstream log(slurp(dir / "soak.jsonl"));
    std::string line;
    int n = 0;
    while (std::getline(log, line)) {
        const nlohmann::json j = nlohmann::json::parse(line);
        EXPECT_TRUE(j["invariants_ok"].get<bool>());
        EXPECT_TRUE(j["mesh_equal"].get<bool>());
        EXPECT_EQ(j["iteration"], 400 * ++n);
    }
    EXPECT_EQ(n, 3);
    const Result bad = run_cli("bench soak " + (dir / "missing.nii.gz").string() + " --image " + (dir / "ph" / "t1.nii.gz").string());
    EXPECT_NE(bad.rc, 0);
    EXPECT_LE(lines(bad.err), 1) << bad.err;
    fs::remove_all(dir);
}
