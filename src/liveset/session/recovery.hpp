// Recovery files: the viewer's unsaved work (φ, the seeds and the threshold parameters) written
// periodically, at exit without saving, and from a crash signal handler, so that the next start can
// offer to restore it. One small binary format of our own (little-endian):
//
//   "LSRECOV1"  u32 version (6)  u32 signal (0: autosave)  i64 unix time
//   u32 n + n bytes: the image's path          i32 dims[3]  f64 spacing[3] origin[3] direction[9]
//   f64 µ ε n α σ  u8 flags  i32 iterations  u32 seeds + (f64 x y z radius) per seed
//   u8 ROI (0: none, 1: one)  u64 its mask_checksum (0 without one)
//   u8 step (0: exact, 1: sleeping)  u8 thin-front rule (0: off, 1: on)
//   u8 coarse start (0: auto, 1: on, 2: off)
//   u64 voxels (= dims product)  f32 φ[voxels]  i8 sparse-field status[voxels]
//   u64 FNV-1a of every byte before it
//
// flags: bit 0 window_from_seeds, bit 1 alpha_automatic (version 1, still read, had bit 0 only;
// versions 1 and 2 have no smoothing σ: read as 0 - with a fixed α as they ran; an automatic α
// takes today's rule, blur included, when the session next builds its speed; versions 1-3 record
// no ROI: RecoveryState::roi_recorded false; versions 1-4 record no step: RecoveryState::step none;
// versions 1-5 record no coarse start: RecoveryState::coarse_start none).
// The viewer's crash path (apps/viewer/crash_recovery) writes the same bytes with async-signal-safe
// calls only, from the pieces in recovery_format. Every read is checked (sizes, magic, checksum,
// geometry) and refused with one line. Standard library only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/coarse_start.hpp"  // CoarseStart
#include "liveset/segment/segmentation.hpp"  // RecordedStep
#include "liveset/session/edit_history.hpp"

namespace liveset {

struct RecoveryState {
    std::string image;           // the image's path, as the viewer opened it
    int signal = 0;              // 0: written by an autosave; otherwise the signal that ended the run
    std::int64_t unix_time = 0;  // when it was written
    SessionMarks marks;          // seeds, parameters, iterations (pristine is not stored: Session::load_recovered finds it)
    // The session's ROI when it was written: its mask_checksum, none without a ROI (read from
    // version 4; older files record nothing: roi_recorded false).
    bool roi_recorded = true;
    std::optional<std::uint64_t> roi_checksum;
    std::optional<RecordedStep> step;  // the session's global step (version 5; older files record none)
    std::optional<CoarseStart> coarse_start;  // the session's coarse start from seeds (version 6; older files record none)
    Grid<float> phi;             // < 0 inside, with the image's geometry
    Grid<std::int8_t> status;    // the sparse field's layer of each point (same lattice)
};

// FNV-1a over a mask's inside/outside bits (1 byte per voxel, 0 or 1): how a recovery file and a
// workspace record the ROI they were written with.
std::uint64_t mask_checksum(const Grid<std::uint8_t>& mask);
// What a work saved with ROI `saved` (none: without one) meets when restored in a session whose
// ROI has checksum `now`: empty when the same, else a short phrase ("saved without a ROI, opened
// with one", "saved with another ROI", "saved with a ROI, opened without one").
std::string roi_difference(std::optional<std::uint64_t> saved, std::optional<std::uint64_t> now);

// What encode_recovery and write_recovery read: a state's parts where they live, so an autosave
// serialises the session's grids without copying them first. A RecoveryState converts to it.
struct RecoveryView {
    RecoveryView(const std::string& image_, int signal_, std::int64_t unix_time_, const SessionMarks& marks_,
                 std::optional<std::uint64_t> roi_checksum_, RecordedStep step_, CoarseStart coarse_start_, const Grid<float>& phi_,
                 const Grid<std::int8_t>& status_)
        : image(image_), signal(signal_), unix_time(unix_time_), marks(marks_), roi_checksum(roi_checksum_), step(step_),
          coarse_start(coarse_start_), phi(phi_), status(status_) {}
    // Implicit on purpose. A state read from a version 1-3 file (roi_recorded false) is written as
    // one saved without a ROI, one from a version 1-4 file (no step) with the default step, and one
    // from a version 1-5 file (no coarse start) with `auto`: nothing re-encodes such a state but
    // the tests and the fuzzer.
    RecoveryView(const RecoveryState& s)
        : RecoveryView(s.image, s.signal, s.unix_time, s.marks, s.roi_checksum, s.step.value_or(RecordedStep{}),
                       s.coarse_start.value_or(CoarseStart::kAuto), s.phi, s.status) {}
    const std::string& image;
    int signal;
    std::int64_t unix_time;
    const SessionMarks& marks;
    std::optional<std::uint64_t> roi_checksum;  // mask_checksum of the session's ROI; none without one
    RecordedStep step;
    CoarseStart coarse_start;
    const Grid<float>& phi;
    const Grid<std::int8_t>& status;
};

// The recovery file for `image` in `dir`: "<file name>-<hash of the absolute path>.lsrecovery", or
// "...-<variant>.lsrecovery" for a variant of the image (e.g. "n4": its bias-corrected copy, so that
// a session on it and one on the raw image never restore each other's work).
std::filesystem::path recovery_path(const std::filesystem::path& dir, const std::string& image, const std::string& variant = {});

// The serialised file (what write_recovery writes).
std::vector<std::uint8_t> encode_recovery(const RecoveryView& state);
// Parses a whole file; throws std::runtime_error with a one-line reason for anything malformed.
RecoveryState decode_recovery(const std::uint8_t* data, std::size_t size);

// Writes atomically (a temporary file next to `path`, then rename). Throws std::runtime_error.
void write_recovery(const std::filesystem::path& path, const RecoveryView& state);
// Throws std::runtime_error (one line naming the file) when missing, unreadable or malformed.
RecoveryState read_recovery(const std::filesystem::path& path);

// The format's pieces, for a writer that cannot allocate when it writes (a signal handler): the
// file is encode_header()'s bytes with the signal (u32) and the time (i64) stored at kSignalOffset
// and kTimeOffset, then φ, then the statuses, then the FNV-1a (Fnv) of every byte before it.
namespace recovery_format {
constexpr std::size_t kSignalOffset = 12;  // u32 signal, then i64 time
constexpr std::size_t kTimeOffset = 16;
constexpr std::size_t kFixedHead = 24;  // magic, version, signal, time

struct Fnv {
    std::uint64_t h = 0xcbf29ce484222325ull;
    void add(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            h ^= p[i];
            h *= 0x100000001b3ull;
        }
    }
};

// The file up to and including the voxel count, with signal 0 and time 0. Throws
// std::runtime_error when the path or the seed list is too long for the format.
std::vector<std::uint8_t> encode_header(const std::string& image, const SessionMarks& marks, std::optional<std::uint64_t> roi_checksum,
                                        RecordedStep step, CoarseStart coarse_start, const Lattice& lattice);
}  // namespace recovery_format

}  // namespace liveset
