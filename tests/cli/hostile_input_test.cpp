// Hostile input, end to end: every CLI command that reads an image is fed every kind of broken file
// (missing, empty, garbage, truncated, wrong magic, 2D, 4D, a header claiming 10^6 x 10^6 x 10^6
// voxels, negative spacing, infinite voxels) in every input slot, and every command gets bad flags and
// impossible output paths (under a file, in a missing folder, on a full disk). The tables below are
// the contract: each case exits non-zero with one line on stderr holding the expected phrase, within
// a bounded time and address space, and leaves no output file behind.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/levelset/shapes.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using namespace liveset;
using liveset::testing::CliResult;
using liveset::testing::lines;

namespace {

// Every run is bounded: 60 s of wall time, and (without AddressSanitizer, whose shadow memory
// needs a huge address space) 4 GB of address space, so an attempt to allocate what a hostile
// header claims fails instead of swapping.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr const char* kLimits = "";
#else
constexpr const char* kLimits = "ulimit -v 4000000; ";
#endif

class HostileInput : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = liveset::testing::scratch_dir("hostile");
        // Good inputs: a 24^3 image with a bright ball, its mask and its φ.
        Grid<float> image(Lattice({24, 24, 24}));
        Grid<std::uint8_t> mask(image.lattice(), 0);
        Grid<float> phi(image.lattice());
        const shapes::Sphere ball({11.5, 11.5, 11.5}, 6.0);
        for (PointIndex i = 0; i < image.size(); ++i) {
            const double d = ball(image.lattice().coord(i).cast<double>());
            image[i] = d < 0 ? 100.0f : 20.0f;
            mask[i] = d < 0;
            phi[i] = static_cast<float>(std::clamp(d, -3.0, 3.0));
        }
        write_image(image, path("good.nii.gz"));
        write_label_image(mask, path("mask.nii.gz"));
        write_image(phi, path("phi.nii.gz"));

        // Broken inputs.
        std::ofstream(path("empty.nii.gz"), std::ios::binary);
        write_bytes("garbage.nii", "this is not an image at all");
        const std::string good = read_bytes(path("good.nii.gz"));
        write_bytes("truncated.nii.gz", good.substr(0, good.size() / 3));
        // Cut short with its gzip trailer kept: the data check runs beside ITK's read (image_io.cpp).
        write_bytes("cut_with_trailer.nii.gz", good.substr(0, good.size() / 2) + good.substr(good.size() - 8));
        write_bytes("bad_magic.nii.gz", "XXXX" + good);
        metaimage("two_d.mha", 2, "8 8", "1 1", 8 * 8 * 4);
        metaimage("four_d.mha", 4, "4 4 4 3", "1 1 1 1", 4 * 4 * 4 * 3 * 4);
        metaimage("huge.mha", 3, "1000000 1000000 1000000", "1 1 1", 64);
        metaimage("negative_spacing.mha", 3, "4 4 4", "1 -1 1", 4 * 4 * 4 * 4);
        std::string inf(4 * 4 * 4 * 4, '\0');  // a scan's NaN is its "no data" (no_data_cli_test); infinite is damage anywhere
        const float q = std::numeric_limits<float>::infinity();
        std::memcpy(inf.data(), &q, sizeof q);
        metaimage("inf.mha", 3, "4 4 4", "1 1 1", 0, inf);
        std::string nan(4 * 4 * 4 * 4, '\0');
        const float n = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(nan.data(), &n, sizeof n);
        metaimage("nan.mha", 3, "4 4 4", "1 1 1", 0, nan);
        write_bytes("a_file", "a file, not a folder");
    }
    static void TearDownTestSuite() { fs::remove_all(dir_); }

    static std::string path(const std::string& name) { return (dir_ / name).string(); }
    static std::string read_bytes(const std::string& p) { return liveset::testing::slurp(p); }
    static void write_bytes(const std::string& name, const std::string& bytes) {
        std::ofstream(path(name), std::ios::binary) << bytes;
    }
    static void metaimage(const std::string& name, int ndims, const std::string& size, const std::string& spacing,
                          std::size_t zero_bytes, const std::string& data = {}) {
        write_bytes(name, "ObjectType = Image\nNDims = " + std::to_string(ndims) + "\nDimSize = " + size +
                              "\nElementSpacing = " + spacing + "\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n" +
                              (data.empty() ? std::string(zero_bytes, '\0') : data));
    }

    // Runs `liveset ARGS` bounded in time and address space.
    static CliResult run(const std::string& args) {
        const std::string cmd = std::string("timeout 60 sh -c '") + kLimits + "exec " + LIVESET_CLI_PATH + " " + args + "'";
        const fs::path out = dir_ / "stdout", err = dir_ / "stderr";
        const int status = std::system((cmd + " >" + out.string() + " 2>" + err.string() + " </dev/null").c_str());
        CliResult r;
        r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        r.out = read_bytes(out.string());
        r.err = read_bytes(err.string());
        return r;
    }

    // The common assertions: non-zero (and not the timeout's 124 or a signal), the phrase on
    // stderr in at most `max_lines` lines (CLI11 adds a "Run with --help" hint to flag errors),
    // never an uncaught exception, and no output left in the work folder.
    static void expect_refused(const std::string& args, const std::string& phrase, int max_lines = 1) {
        SCOPED_TRACE(args);
        for (const auto& e : fs::directory_iterator(dir_))
            if (e.path().filename().string().rfind("out", 0) == 0) fs::remove_all(e.path());
        const CliResult r = run(args);
        EXPECT_NE(r.rc, 0);
        EXPECT_NE(r.rc, 124) << "timed out";
        EXPECT_LT(r.rc, 128) << "killed by a signal";
        EXPECT_NE(r.err.find(phrase), std::string::npos) << "stderr: " << r.err;
        EXPECT_LE(lines(r.err), max_lines) << r.err;
        EXPECT_EQ(r.err.find("terminate called"), std::string::npos) << r.err;
        for (const auto& e : fs::directory_iterator(dir_)) {
            const std::string name = e.path().filename().string();
            EXPECT_FALSE(name.rfind("out", 0) == 0 && name != "stdout") << "left " << name;
        }
    }

    static fs::path dir_;
};

fs::path HostileInput::dir_;

struct BrokenFile {
    const char* name;
    const char* phrase;
};

// The broken files and the phrase each must produce.
const std::vector<BrokenFile> kBrokenFiles = {
    {"missing.nii.gz", "no such file"},
    {"empty.nii.gz", "file is empty"},
    {"garbage.nii", "unknown image format or damaged header"},
    {"truncated.nii.gz", "corrupt or truncated"},
    {"cut_with_trailer.nii.gz", "corrupt or truncated"},
    {"bad_magic.nii.gz", "unknown image format or damaged header"},
    {"two_d.mha", "is a 2D image"},
    {"four_d.mha", "is a 4D image"},
    {"huge.mha", "image is too large"},
    {"negative_spacing.mha", "invalid spacing"},
    {"inf.mha", "infinite"},
};

// Every input slot of every command that reads an image; {} is the broken file.
const std::vector<std::string> kImageSlots = {
    "mesh {} --out OUT/s.ply",
    "segment {} --seed 11,11,11 --mu 0.5 --epsilon 0.3 --iterations 3 --quiet --out-mask OUT/m.nii.gz",
    "segment GOOD --roi {} --seed 11,11,11 --iterations 3 --quiet --out-mask OUT/m.nii.gz",
    "segment GOOD --init-mask {} --iterations 3 --quiet --out-mask OUT/m.nii.gz",
    "eval --mask {} --truth MASK",
    "eval --mask MASK --truth {}",
    "repair {} --image GOOD --target 11,11,17 --steps 2 --out-mask OUT/m.nii.gz",
    "repair PHI --image {} --target 11,11,17 --steps 2 --out-mask OUT/m.nii.gz",
    "repair PHI --image GOOD --roi {} --target 11,11,17 --steps 2 --out-mask OUT/m.nii.gz",
};

std::string fill(std::string s, const std::string& file, const std::string& dir) {
    const auto replace = [&](const std::string& key, const std::string& value) {
        for (std::size_t at; (at = s.find(key)) != std::string::npos;) s.replace(at, key.size(), value);
    };
    replace("{}", dir + "/" + file);
    replace("GOOD", dir + "/good.nii.gz");
    replace("MASK", dir + "/mask.nii.gz");
    replace("PHI", dir + "/phi.nii.gz");
    replace("OUT/", dir + "/out_");
    return s;
}

}  // namespace

TEST_F(HostileInput, GoodInputsWork) {  // the tables below would pass vacuously if these failed
    for (const std::string& slot : {std::string("mesh MASK --out OUT/s.ply"), std::string("eval --mask MASK --truth MASK"),
                                    std::string("repair PHI --image GOOD --target 11,11,17 --steps 2 --quiet --out-mask OUT/m.nii.gz")}) {
        const CliResult r = run(fill(slot, "", dir_.string()));
        EXPECT_EQ(r.rc, 0) << slot << ": " << r.err;
    }
}

TEST_F(HostileInput, EveryBrokenImageInEverySlot) {
    for (const std::string& slot : kImageSlots)
        for (const BrokenFile& b : kBrokenFiles) expect_refused(fill(slot, b.name, dir_.string()), b.phrase);
}

// NaN is a scan's "no data" (no_data_cli_test), but damage in a mask or a level set: every slot
// but the scan's (segment's image, repair's and holes' --image) refuses it.
TEST_F(HostileInput, NanInAMaskOrALevelSetIsRefused) {
    for (const std::string& slot : kImageSlots) {
        if (slot.rfind("segment {}", 0) == 0 || slot.find("--image {}") != std::string::npos) continue;
        expect_refused(fill(slot, "nan.mha", dir_.string()), "NaN or infinite");
    }
    expect_refused(fill(std::string("holes {} --image GOOD"), "nan.mha", dir_.string()), "NaN or infinite");
}

TEST_F(HostileInput, ImpossibleOutputs) {
    const std::string d = dir_.string();
    const struct {
        std::string args, phrase;
    } cases[] = {
        {"mesh " + d + "/mask.nii.gz --out " + d + "/a_file/out_s.ply", "a_file does not exist"},
        {"mesh " + d + "/mask.nii.gz --out " + d + "/out_missing/s.ply", "does not exist"},
        {"mesh " + d + "/mask.nii.gz --out " + d + "/out_s.txt", "unknown mesh format"},
        {"segment " + d + "/good.nii.gz --seed 11,11,11 --quiet --out-mask " + d + "/a_file/out_m.nii.gz", "a_file does not exist"},
        {"segment " + d + "/good.nii.gz --seed 11,11,11 --quiet --out-mask " + d + "/out_m.png", "unknown image format"},
        {"repair " + d + "/phi.nii.gz --image " + d + "/good.nii.gz --target 11,11,17 --out-mask " + d + "/a_file/out_m.nii.gz",
         "a_file does not exist"},
        {"repair " + d + "/phi.nii.gz --image " + d + "/good.nii.gz --target 11,11,17 --out-mask " + d + "/out_m.nii.gz --log " + d +
             "/a_file/out_l.jsonl",
         "a_file does not exist"},
        {"demo --out " + d + "/a_file/out_demo", "cannot create output folder"},
    };
    for (const auto& c : cases) expect_refused(c.args, c.phrase);
}

TEST_F(HostileInput, FullDiskLeavesNothing) {
    const fs::path mnt = dir_ / "out_tiny";
    fs::create_directories(mnt);
    if (::mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=16k") != 0)
        GTEST_SKIP() << "cannot mount a small tmpfs (" << std::strerror(errno) << ")";
    struct Unmount {
        fs::path at;
        ~Unmount() { ::umount2(at.c_str(), MNT_DETACH); }
    } unmount{mnt};
    const std::string d = dir_.string(), m = mnt.string();
    for (const std::string& args :
         {"segment " + d + "/good.nii.gz --seed 11,11,11 --iterations 3 --quiet --out-mask " + m + "/m.nii --out-phi " + m + "/phi.nii",
          "mesh " + d + "/mask.nii.gz --out " + m + "/s.obj", "phantom --size 48 --quiet --out " + m + "/ph"}) {
        SCOPED_TRACE(args);
        const CliResult r = run(args);
        EXPECT_NE(r.rc, 0);
        EXPECT_LE(lines(r.err), 1) << r.err;
        EXPECT_TRUE(r.err.find("space") != std::string::npos || r.err.find("disk full") != std::string::npos) << r.err;
        std::size_t files = 0;
        for (const auto& e : fs::recursive_directory_iterator(mnt)) files += e.is_regular_file();
        EXPECT_EQ(files, 0u) << "a partial output was left on the full disk";
        fs::remove_all(m + "/ph");
    }
}

TEST_F(HostileInput, BadFlagsAndValues) {
    const std::string d = dir_.string(), g = d + "/good.nii.gz", p = d + "/phi.nii.gz", o = " --out-mask " + d + "/out_m.nii.gz";
    const struct {
        std::string args, phrase;
    } cases[] = {
        {"--threads -2 mesh " + g + " --out " + d + "/out_s.ply", "--threads"},
        {"--threads abc mesh " + g + " --out " + d + "/out_s.ply", "--threads"},
        {"segment " + g + " --seed 11,11" + o, "seed"},
        {"segment " + g + " --seed 11,11,11:-2" + o, "seed"},
        {"segment " + g + " --seed 500,11,11" + o, "outside the image"},
        {"segment " + g + " --seed nan,1,1" + o, "seed"},
        {"segment " + g + " --seed 11,11,11 --alpha 1.5" + o, "alpha"},
        {"segment " + g + " --seed 11,11,11 --epsilon 0" + o, "epsilon"},
        {"segment " + g + " --seed 11,11,11 --n -1" + o, "n must be in (0, 100]"},
        {"segment " + g + " --seed 11,11,11 --iterations 0" + o, "--iterations"},
        {"segment " + g + " --seed 11,11,11 --mu 0.5 --mu-raw 50" + o, "mu"},
        {"segment " + g + o, "seed"},
        {"segment " + g + " --seed 11,11,11", "--out"},
        {"repair " + p + " --image " + g + " --target 11,11,17 --p 1.5" + o, "p"},
        {"repair " + p + " --image " + g + " --target 11,11,17 --agents 0" + o, "agents"},
        {"repair " + p + " --image " + g + " --target 11,11,17 --amount 2" + o, "edit_amount"},
        {"repair " + p + " --image " + g + " --target 11,11,17@x" + o, "step"},
        {"repair " + p + " --image " + g + " --target 11,11,17 --decision maybe" + o, "decision"},
        {"repair " + p + " --image " + g + o, "--target"},
        {"eval --mask " + d + "/mask.nii.gz --truth " + d + "/mask.nii.gz --label 300", "label"},
        {"eval --mask " + d + "/mask.nii.gz --truth " + d + "/mask.nii.gz --inner-label 3", "--inner-label"},
        {"phantom --size 8 --out " + d + "/out_ph", "size"},
        {"phantom --noise nan --out " + d + "/out_ph", "noise"},
        {"demo --size 1000 --out " + d + "/out_demo", "size"},
        {"bench fig3 --lattice 2 --out " + d + "/out_fig3", "lattice"},
        {"segment " + g + " --seed 11,11,11 --no-such-flag" + o, "no-such-flag"},
    };
    for (const auto& c : cases) expect_refused(c.args, c.phrase, 2);
}
