// Autosave and recovery of the viewer's unsaved work.
#include "autosave.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cstdlib>
#include <ctime>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace liveset::viewer {

namespace {

std::string local_time(std::int64_t unix_time) {
    const std::time_t t = static_cast<std::time_t>(unix_time);
    std::tm tm{};
    if (!localtime_r(&t, &tm)) return "an unknown time";
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M", &tm);
    return text;
}

const char* signal_name(int sig) {
    switch (sig) {
        case 0: return nullptr;
        case 1: return "SIGHUP";
        case 2: return "SIGINT";
        case 4: return "SIGILL";
        case 6: return "SIGABRT";
        case 7: return "SIGBUS";
        case 8: return "SIGFPE";
        case 11: return "SIGSEGV";
        case 15: return "SIGTERM";
        default: return "a signal";
    }
}

}  // namespace

std::filesystem::path default_recovery_dir() {
    if (const char* state = std::getenv("XDG_STATE_HOME"); state && *state) return std::filesystem::path(state) / "liveset" / "recovery";
    if (const char* home = std::getenv("HOME"); home && *home) return std::filesystem::path(home) / ".local" / "state" / "liveset" / "recovery";
    return {};
}

void Autosave::attach(Session* session, const std::string& image_path, bool corrected) {
    crash_.reset();
    offer_.reset();
    session_ = nullptr;
    image_ = image_path;
    exited_ = restored_ = false;
    file_.clear();
    if (!enabled() || !session || image_.empty()) return;
    session_ = session;
    roi_checksum_ = session->roi() ? std::optional(mask_checksum(*session->roi())) : std::nullopt;
    std::error_code ec;
    std::filesystem::create_directories(config_.dir, ec);
    if (ec) {
        message_ = fmt::format("autosave is off: cannot create {} ({})", config_.dir.string(), ec.message());
        session_ = nullptr;
        return;
    }
    file_ = recovery_path(config_.dir, image_, corrected ? "n4" : "");
    clean_revision_ = written_revision_ = session_->revision();
    tracked_revision_ = ~std::uint64_t{0};
    last_write_ = std::chrono::steady_clock::now();
    if (std::filesystem::exists(file_, ec)) {
        try {
            RecoveryState state = read_recovery(file_);
            if (!state.phi.lattice().same_geometry(session_->lattice(), 1e-3))
                message_ = fmt::format("ignoring the recovery file {}: its geometry ({}) is not the image's", file_.string(),
                                       state.phi.lattice().describe());
            else
                offer_ = std::move(state);
        } catch (const std::exception& e) {
            message_ = fmt::format("ignoring a damaged recovery file: {}", e.what());
        }
    }
    if (offer_ && config_.recover) restore();
    if (!offer_) crash_.emplace(file_);
}

std::string Autosave::offer_summary() const {
    if (!offer_) return {};
    const SessionMarks& m = offer_->marks;
    std::string how = offer_->signal ? fmt::format(", saved when the viewer received {}", signal_name(offer_->signal)) : "";
    // Older files record no ROI: nothing to compare.
    const std::string roi = offer_->roi_recorded ? roi_difference(offer_->roi_checksum, roi_checksum_) : "";
    return fmt::format("unsaved work from {} ({} seed(s), {} iteration(s){}) in {}{}", local_time(offer_->unix_time), m.seeds.size(),
                       m.iterations, how, file_.string(), roi.empty() ? "" : "; " + roi);
}

bool Autosave::restore() {
    if (!offer_ || !session_) return false;
    message_.clear();
    bool step_changed = false;
    try {
        const ContinuedRun run = continued_run();  // decided and checked first: nothing after the load throws
        if (!session_->load_recovered(offer_->phi, offer_->status, offer_->marks))
            message_ = "the recovery file's sparse field was inconsistent: restored from the signs of its phi";
        step_changed = run.step || run.coarse_start;
        if (run.step) session_->set_step(*run.step);
        if (run.coarse_start) session_->set_coarse_start(*run.coarse_start);
        if (!run.note.empty()) message_ = message_.empty() ? run.note : message_ + "; " + run.note;
    } catch (const std::exception& e) {
        message_ = fmt::format("cannot restore {}: {}", file_.string(), e.what());
        offer_.reset();
        crash_.emplace(file_);
        return false;
    }
    message_ = fmt::format("restored {}{}", offer_summary(), message_.empty() ? "" : " (" + message_ + ")");
    offer_.reset();
    restored_ = true;
    // The restored work is still unsaved: keep the file until the user saves.
    clean_revision_ = ~std::uint64_t{0};
    // A changed step or coarse start is written with the next autosave (the crash path takes it at once).
    written_revision_ = step_changed ? ~std::uint64_t{0} : session_->revision();
    crash_.emplace(file_);
    return true;
}

Autosave::ContinuedRun Autosave::continued_run() const {
    // The work continues with the step and the coarse start it was saved with (a file from before
    // session 73 records no step, one from before session 83 no coarse start: the command line's
    // there), but for what --step, --thin-fronts, --no-thin-fronts or --coarse-start ask.
    ContinuedRun run;
    std::vector<std::string> asked, kept;
    if (offer_->step) {
        const RecordedStep now = recorded_step(session_->options().segmentation.step), saved = *offer_->step;
        const RecordedStep next{config_.step_given ? now.sleeping : saved.sleeping, config_.thin_fronts_given ? now.thin_fronts : saved.thin_fronts};
        if (next != now) {
            run.step = step_options(next);
            validate(*run.step);
        }
        if (next != saved) asked.push_back(fmt::format("{} as asked (saved with {})", describe(next), describe(saved)));
        else if (next != now) kept.push_back(describe(saved));
    }
    if (offer_->coarse_start) {
        const CoarseStart now = session_->options().coarse_start, saved = *offer_->coarse_start;
        const CoarseStart next = config_.coarse_start_given ? now : saved;
        if (next != now) run.coarse_start = next;
        if (next != saved) asked.push_back(fmt::format("--coarse-start {} as asked (saved with --coarse-start {})", to_string(next), to_string(saved)));
        else if (next != now) kept.push_back("--coarse-start " + to_string(saved));
    }
    if (!asked.empty())
        run.note = fmt::format("continued with {}: from here it steps unlike the saved run", fmt::join(asked, " and "));
    else if (!kept.empty())
        run.note = fmt::format("continued with its saved {}", fmt::join(kept, " "));
    return run;
}

void Autosave::discard() {
    if (!offer_) return;
    offer_.reset();
    remove_file();
    message_ = "discarded the recovery file";
    crash_.emplace(file_);
}

bool Autosave::dirty() const { return session_ && session_->revision() != clean_revision_; }

void Autosave::tick() {
    if (!session_ || offer_ || exited_ || !crash_) return;
    const std::uint64_t revision = session_->revision();
    if (!dirty()) {
        if (tracked_revision_ != revision) crash_->untrack();
        tracked_revision_ = revision;
        return;
    }
    if (tracked_revision_ != revision) {
        try {
            crash_->track(image_, session_->marks(), roi_checksum_, recorded_step(session_->options().segmentation.step),
                          session_->options().coarse_start, session_->field().phi(), session_->field().status());
        } catch (const std::exception& e) {
            message_ = e.what();
        }
        tracked_revision_ = revision;
    }
    const auto now = std::chrono::steady_clock::now();
    if (revision != written_revision_ && std::chrono::duration<double>(now - last_write_).count() >= config_.interval_seconds)
        write("autosaved");
}

void Autosave::write(const char* why) {
    try {
        write_recovery(file_, RecoveryView(image_, 0, static_cast<std::int64_t>(std::time(nullptr)), session_->marks(), roi_checksum_,
                                           recorded_step(session_->options().segmentation.step), session_->options().coarse_start,
                                           session_->field().phi(), session_->field().status()));
        message_ = fmt::format("{} unsaved work in {}", why, file_.string());
        routine_ = !exited_;
    } catch (const std::exception& e) {
        message_ = fmt::format("autosave failed: {}", e.what());
    }
    written_revision_ = session_->revision();
    last_write_ = std::chrono::steady_clock::now();
}

void Autosave::remove_file() {
    std::error_code ec;
    if (!file_.empty()) std::filesystem::remove(file_, ec);
}

void Autosave::mark_saved() {
    if (!session_ || offer_) return;
    clean_revision_ = session_->revision();
    remove_file();
    if (crash_) crash_->untrack();
    tracked_revision_ = clean_revision_;
}

void Autosave::at_exit() {
    if (!session_ || exited_) return;
    exited_ = true;
    if (crash_) crash_->untrack();
    if (offer_) return;  // the user did not choose: the file stays for next time
    if (dirty())
        write("kept the");
    else
        remove_file();
}

std::string Autosave::take_message(bool* routine) {
    if (routine) *routine = routine_;
    routine_ = false;
    return std::exchange(message_, {});
}

}  // namespace liveset::viewer
