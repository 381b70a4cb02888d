// No lost work in the viewer: unsaved changes of the session (φ, seeds, parameters) go to a
// recovery file every few minutes, when the viewer exits without saving, and from a crash or
// termination signal (liveset/session/recovery.hpp). When the viewer opens an image that has a
// recovery file, it offers to restore it (a window asks; `--recover` restores without asking);
// saving the mask or φ removes the file. The undo history is not kept across runs.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "crash_recovery.hpp"
#include "liveset/session/recovery.hpp"
#include "liveset/session/session.hpp"

namespace liveset::viewer {

struct AutosaveConfig {
    std::filesystem::path dir;      // empty: no autosave and no recovery offer
    double interval_seconds = 120;  // between periodic writes of unsaved work (0: at every change)
    bool recover = false;           // restore a recovery file without asking
    // --step given, --thin-fronts or --no-thin-fronts given, --coarse-start given: a restored file
    // continues with the command line's step kind, rule or coarse start there, its saved ones elsewhere.
    bool step_given = false, thin_fronts_given = false, coarse_start_given = false;
};

// $XDG_STATE_HOME/liveset/recovery, else ~/.local/state/liveset/recovery (empty without HOME).
std::filesystem::path default_recovery_dir();

class Autosave {
public:
    explicit Autosave(AutosaveConfig config) : config_(std::move(config)) {}
    Autosave(const Autosave&) = delete;
    Autosave& operator=(const Autosave&) = delete;

    bool enabled() const { return !config_.dir.empty(); }
    // A new session on `image_path` (the path as given; call at_exit() before the previous session
    // goes), `corrected`: on its N4-corrected copy (a recovery file of its own). Looks for its
    // recovery file: a readable one matching the image becomes the pending offer (restored at once
    // with `recover`); a damaged or mismatching one is reported in message() and will be replaced by
    // this run's autosaves.
    void attach(Session* session, const std::string& image_path, bool corrected = false);

    // The pending offer: a recovery file awaiting the user's choice (autosave waits meanwhile).
    bool offer_pending() const { return offer_.has_value(); }
    // "unsaved work from 2026-11-23 11:02 (3 seeds, 120 iterations, ...)", and how its ROI differs
    // from this session's ("; saved with another ROI", roi_difference).
    std::string offer_summary() const;
    // Loads the offered state into the session (false + message() when it cannot).
    bool restore();
    void discard();  // removes the recovery file

    // Every frame: keeps the crash handler's copy of the marks current and writes the recovery file
    // when the session changed and the interval has passed.
    void tick();
    void mark_saved();  // the user saved the mask or φ: the work is safe, the file goes
    // At exit: unsaved work is written (and kept for the next start); otherwise the file goes.
    void at_exit();

    const std::filesystem::path& file() const { return file_; }
    // The last thing worth telling the user ("" when nothing new); clears it. `routine` is set for
    // periodic autosaves (status line only; the rest also goes to stderr when headless or exiting).
    std::string take_message(bool* routine = nullptr);
    bool restored() const { return restored_; }

private:
    bool dirty() const;
    // restore()'s step and coarse start: the offer's (none where the session's is already the one
    // to take) and the note that says so, or that the command line asked for another.
    struct ContinuedRun {
        std::optional<StepOptions> step;
        std::optional<CoarseStart> coarse_start;
        std::string note;
    };
    ContinuedRun continued_run() const;
    void write(const char* why);
    void remove_file();

    AutosaveConfig config_;
    Session* session_ = nullptr;
    std::string image_;
    std::optional<std::uint64_t> roi_checksum_;  // the session's ROI (mask_checksum), recorded in the file
    std::filesystem::path file_;
    std::optional<RecoveryState> offer_;
    std::optional<CrashRecovery> crash_;
    std::uint64_t clean_revision_ = 0, written_revision_ = 0, tracked_revision_ = ~std::uint64_t{0};
    std::chrono::steady_clock::time_point last_write_{};
    std::string message_;
    bool routine_ = false;
    bool exited_ = false, restored_ = false;
};

}  // namespace liveset::viewer
