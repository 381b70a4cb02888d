// The viewer's crash path: on a fatal or termination signal, the tracked session state is written as
// a recovery file (liveset/session/recovery.hpp's format) with async-signal-safe calls only, then
// the signal takes its default course.
#pragma once

#include <filesystem>
#include <string>

#include "liveset/session/recovery.hpp"

namespace liveset {

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
    // outlive the registration or be replaced first); the image path, the marks and the ROI's
    // checksum (mask_checksum; none without a ROI), the session's step and coarse start are serialised now.
    // Call again whenever the marks change or the grids move.
    void track(const std::string& image, const SessionMarks& marks, std::optional<std::uint64_t> roi_checksum, RecordedStep step,
               CoarseStart coarse_start, const Grid<float>& phi, const Grid<std::int8_t>& status);
    void untrack();  // a crash now writes nothing (e.g. the work was saved)
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

}  // namespace liveset
