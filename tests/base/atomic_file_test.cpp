// The atomic file writer: a file is replaced whole or not at all; a failed or interrupted write
// leaves the old file and no temporary; the temporary keeps the target's extension; a fatal-signal
// handler can remove the temporaries of writes in flight.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "liveset/base/atomic_file.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;

using testing::scratch_dir;

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::size_t entries(const fs::path& dir) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

TEST(AtomicFile, ReplacesTheFileWholeAndLeavesNothingElse) {
    const fs::path dir = scratch_dir("atomic_whole");
    const fs::path target = dir / "report.json";
    write_file_atomically(target, "first");
    write_file_atomically(target, std::string(100000, 'x'));
    EXPECT_EQ(slurp(target), std::string(100000, 'x'));
    EXPECT_EQ(entries(dir), 1u);
    fs::remove_all(dir);
}

TEST(AtomicFile, AFailedWriteKeepsTheOldFileAndNoTemporary) {
    const fs::path dir = scratch_dir("atomic_failed");
    const fs::path target = dir / "mesh.ply";
    write_file_atomically(target, "old");
    EXPECT_THROW(write_file_atomically(target,
                                       [](std::ostream& os) {
                                           os << "half of it";
                                           throw std::runtime_error("the writer gave up");
                                       }),
                 std::runtime_error);
    EXPECT_EQ(slurp(target), "old");
    EXPECT_EQ(entries(dir), 1u);
    try {  // a folder that does not exist: the system's reason, nothing created
        write_file_atomically(dir / "missing" / "x.txt", "x");
        ADD_FAILURE() << "wrote into a missing folder";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
    }
    EXPECT_EQ(entries(dir), 1u);
    fs::remove_all(dir);
}

TEST(AtomicFile, TheTemporaryKeepsTheExtensionAndGoesWithoutACommit) {
    const fs::path dir = scratch_dir("atomic_temp");
    {
        AtomicFile file(dir / "seg.nii.gz");
        EXPECT_EQ(file.temp_path().parent_path(), dir);
        EXPECT_EQ(file_extension(file.temp_path().filename().string()), ".nii.gz");
        EXPECT_EQ(file.temp_path().filename().string().front(), '.');  // hidden
        file.create();
        std::ofstream(file.temp_path(), std::ios::binary) << "data";
        EXPECT_EQ(entries(dir), 1u);
    }
    EXPECT_EQ(entries(dir), 0u);  // no commit: removed
    {
        AtomicFile file(dir / "seg.nii.gz");
        file.create();
        std::ofstream(file.temp_path(), std::ios::binary) << "data";
        file.commit();
    }
    EXPECT_EQ(slurp(dir / "seg.nii.gz"), "data");
    EXPECT_EQ(entries(dir), 1u);
    fs::remove_all(dir);
}

TEST(AtomicFile, ASignalHandlerCanDiscardTheWritesInFlight) {
    const fs::path dir = scratch_dir("atomic_signal");
    AtomicFile a(dir / "a.lsrecovery"), b(dir / "b.png");
    a.create();
    b.create();
    EXPECT_EQ(entries(dir), 2u);
    discard_temporaries();  // what the viewer's crash handler calls before the process dies
    EXPECT_EQ(entries(dir), 0u);
    fs::remove_all(dir);
}

TEST(AtomicFile, ExtensionsAreTheFormatsOnes) {
    EXPECT_EQ(file_extension("seg.nii.gz"), ".nii.gz");
    EXPECT_EQ(file_extension("SEG.NII.GZ"), ".NII.GZ");
    EXPECT_EQ(file_extension("a.mha"), ".mha");
    EXPECT_EQ(file_extension("noext"), "");
    EXPECT_EQ(file_extension(".hidden"), "");
}

}  // namespace
}  // namespace liveset
