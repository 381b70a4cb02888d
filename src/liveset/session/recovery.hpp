// Recovery files: the viewer's unsaved work (φ, the seeds and the threshold parameters) written
// periodically, at exit without saving, and from a crash signal handler, so that the next start can
// offer to restore it. One small binary format of our own (little-endian):
//
//   "LSRECOV1"  u32 version (1)  u32 signal (0: autosave)  i64 unix time
//   u32 n + n bytes: the image's path          i32 dims[3]  f64 spacing[3] origin[3] direction[9]
//   f64 µ ε n α  u8 window_from_seeds  i32 iterations  u32 seeds + (f64 x y z radius) per seed
//   u64 voxels (= dims product)  f32 φ[voxels]  i8 sparse-field status[voxels]
//   u64 FNV-1a of every byte before it
//
// The crash path (CrashRecovery) writes the same bytes with async-signal-safe calls only (open,
// write, rename): the header is serialised beforehand, φ and status are read where they live. Every read is
// checked (sizes, magic, checksum, geometry) and refused with one line. Standard library only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/session/edit_history.hpp"

namespace liveset {

struct RecoveryState {
    std::string image;           // the image's path, as the viewer opened it
    int signal = 0;              // 0: written by an autosave; otherwise the signal that ended the run
    std::int64_t unix_time = 0;  // when it was written
    SessionMarks marks;          // seeds, parameters, iterations (pristine is not stored: false)
    Grid<float> phi;             // < 0 inside, with the image's geometry
    Grid<std::int8_t> status;    // the sparse field's layer of each point (same lattice)
};

// What encode_recovery and write_recovery read: a state's parts where they live, so an autosave
// serialises the session's grids without copying them first. A RecoveryState converts to it.
struct RecoveryView {
    RecoveryView(const std::string& image_, int signal_, std::int64_t unix_time_, const SessionMarks& marks_,
                 const Grid<float>& phi_, const Grid<std::int8_t>& status_)
        : image(image_), signal(signal_), unix_time(unix_time_), marks(marks_), phi(phi_), status(status_) {}
    RecoveryView(const RecoveryState& s)  // implicit on purpose
        : RecoveryView(s.image, s.signal, s.unix_time, s.marks, s.phi, s.status) {}
    const std::string& image;
    int signal;
    std::int64_t unix_time;
    const SessionMarks& marks;
    const Grid<float>& phi;
    const Grid<std::int8_t>& status;
};

// The recovery file for `image` in `dir`: "<file name>-<hash of the absolute path>.lsrecovery".
std::filesystem::path recovery_path(const std::filesystem::path& dir, const std::string& image);

// The serialised file (what write_recovery writes).
std::vector<std::uint8_t> encode_recovery(const RecoveryView& state);
// Parses a whole file; throws std::runtime_error with a one-line reason for anything malformed.
RecoveryState decode_recovery(const std::uint8_t* data, std::size_t size);

// Writes atomically (a temporary file next to `path`, then rename). Throws std::runtime_error.
void write_recovery(const std::filesystem::path& path, const RecoveryView& state);
// Throws std::runtime_error (one line naming the file) when missing, unreadable or malformed.
RecoveryState read_recovery(const std::filesystem::path& path);

// Writes the recovery file of the registered level set when the process receives a fatal signal
// (SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT) or a termination request (SIGTERM, SIGINT, SIGHUP),
// then lets the signal take its default course. One instance at a time (a second throws
// std::logic_error); the destructor restores the previous handlers.
class CrashRecovery {
public:
    explicit CrashRecovery(std::filesystem::path path);
    ~CrashRecovery();
    CrashRecovery(const CrashRecovery&) = delete;
    CrashRecovery& operator=(const CrashRecovery&) = delete;

    // What a crash would save: `phi` and `status` are read in place by the handler (they must
    // outlive the registration or be replaced first); the image path and marks are serialised now.
    // Call again whenever the marks change or the grids move.
    void track(const std::string& image, const SessionMarks& marks, const Grid<float>& phi, const Grid<std::int8_t>& status);
    void untrack();  // a crash now writes nothing (e.g. the work was saved)
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace liveset
