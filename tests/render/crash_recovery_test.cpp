// The viewer's crash path: a crash or termination signal writes the tracked state as a recovery
// file before the process dies; an untracked state writes nothing; one handler at a time.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>

#include "crash_recovery.hpp"
#include "session/recovery_samples.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;

// The child process dies by `sig` after the tracking was set up in the parent (no allocation after
// fork); the parent then reads what the handler wrote.
int die_by(int sig) {
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::raise(sig);
        ::_exit(99);  // not reached: the signal's default action ends the process
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFSIGNALED(status) ? WTERMSIG(status) : -WEXITSTATUS(status);
}

TEST(Recovery, ACrashOrTerminationSignalWritesTheTrackedState) {
    const fs::path dir = fresh_dir("crash");
    const RecoveryState s = sample_state();
    for (int sig : {SIGSEGV, SIGABRT, SIGTERM, SIGINT}) {
        const fs::path path = dir / ("crash" + std::to_string(sig) + ".lsrecovery");
        CrashRecovery crash(path);
        crash.track(s.image, s.marks, s.roi_checksum, *s.step, *s.coarse_start, s.phi, s.status);
        ASSERT_EQ(die_by(sig), sig) << "signal " << sig;
        ASSERT_TRUE(fs::exists(path)) << "signal " << sig << " wrote no recovery file";
        EXPECT_FALSE(fs::exists(path.string() + ".part"));
        const RecoveryState got = read_recovery(path);
        EXPECT_EQ(got.signal, sig);
        EXPECT_GT(got.unix_time, 1700000000);
        RecoveryState expected = s;
        expected.signal = sig;
        expected.unix_time = got.unix_time;
        expect_same(expected, got);
    }
    {  // untracked (the work was saved): the signal writes nothing
        const fs::path path = dir / "untracked.lsrecovery";
        CrashRecovery crash(path);
        crash.track(s.image, s.marks, s.roi_checksum, *s.step, *s.coarse_start, s.phi, s.status);
        crash.untrack();
        ASSERT_EQ(die_by(SIGTERM), SIGTERM);
        EXPECT_FALSE(fs::exists(path));
    }
    EXPECT_THROW(
        {
            CrashRecovery a(dir / "a");
            CrashRecovery b(dir / "b");
        },
        std::logic_error);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace liveset
