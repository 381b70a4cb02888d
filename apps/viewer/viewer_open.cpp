// Opening an image from the panel: read and N4 on a worker thread (the window keeps drawing and
// can cancel), then the new session swapped in by a frame. Cancel stops N4 at its next iteration;
// reading the file, the brain mask N4 is fitted in and the session's set-up run to their end
// (seconds at most for a large DICOM series) and their result is dropped.
#include <fmt/core.h>

#include <filesystem>
#include <system_error>
#include <utility>

#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

namespace {
constexpr int kOpenPollMs = 40;  // a frame waits this long for the worker (the window's pace meanwhile)
}  // namespace

// What the worker hands over: the session on the prepared image, or why there is none.
struct Viewer::Opened {
    std::unique_ptr<Session> session;
    bool corrected = false;    // N4 ran
    bool oriented = true;      // the header gave an orientation
    bool brain_roi = false;    // the automatic brain mask bounds the front (the default on a head)
    std::string bias_skipped;  // the default correction's warning, when it did not run
    std::string no_brain;      // PreparedImage::no_brain: the default ROI gave up on a head
    std::string no_data;       // Scan::note: the image's NaN voxels, read as its outside
    std::string error;         // the image could not be opened
};

bool Viewer::open_image(const std::string& path) {
    if (opening()) return fail("still opening " + open_job_path_ + " (Cancel first)");
    open_cancel_ = std::make_shared<std::atomic<bool>>(false);
    const auto cancel = open_cancel_;
    const cli::BiasCorrection mode = cli::bias_mode(config_.bias_correct, false);
    const SessionOptions options = config_.session;
    const std::string roi_arg = config_.roi_none ? "none" : "";  // the command line's --roi none, else the default
    const auto failed = [](std::string why) noexcept -> std::shared_ptr<Opened> {
        try {
            auto out = std::make_shared<Opened>();
            out->error = std::move(why);
            return out;
        } catch (...) {
            return nullptr;  // out of memory: poll_open says so
        }
    };
    const auto work = [path, cancel, mode, options, roi_arg, failed]() -> std::shared_ptr<Opened> {
        try {
            auto out = std::make_shared<Opened>();
            cli::Scan scan = cli::read_scan(path);
            Grid<float>& image = scan.image;
            const ImageHeader& header = scan.header;
            out->no_data = scan.note(path);
            if (cancel->load()) return out;
            out->oriented = header.orientation_known;
            cli::BrainLookup lookup;
            lookup.options = cli::brain_mask_options(header);
            std::optional<cli::Roi> roi = cli::load_roi(roi_arg, image, "--roi", &lookup);  // as `view IMAGE [--roi none]` (view_command.cpp)
            if (cancel->load()) return out;
            cli::PreparedImage prepared = cli::prepare_image(image, roi, mode, cancel.get(), &lookup, scan.no_data_mask());
            if (cancel->load()) return out;
            out->corrected = prepared.bias.has_value();
            out->bias_skipped = prepared.bias_skipped;
            out->no_brain = prepared.no_brain;
            out->brain_roi = roi.has_value();
            SessionOptions with_region = options;
            with_region.model_region_is_brain = prepared.fit_is_brain(roi);
            with_region.model_region_grey_brighter = prepared.grey_brighter;
            with_region.brain_mask = lookup.options;
            with_region.model_region = std::move(prepared.fit_region);
            std::optional<Grid<std::uint8_t>> roi_mask;
            if (roi) roi_mask = std::move(roi->mask);
            out->session = std::make_unique<Session>(std::move(image), with_region, std::move(roi_mask));
            return out;
        } catch (const std::exception& e) {
            return failed(e.what());
        } catch (...) {
            return failed("cannot open " + path + ": unknown error");
        }
    };
    try {
        open_job_ = std::async(std::launch::async, work);
    } catch (const std::system_error& e) {  // no thread to run it on
        open_cancel_.reset();
        return fail("cannot open " + path + ": " + e.what());
    }
    open_job_path_ = path;
    open_started_ = std::chrono::steady_clock::now();
    message_ = "opening " + path + "...";
    message_is_error_ = false;
    log_.add("opening", {{"path", path}});
    request_redraw();
    return true;
}

void Viewer::cancel_open() {
    if (open_cancel_) open_cancel_->store(true);
}

void Viewer::poll_open(bool wait) {
    if (!opening()) return;
    if (open_job_.wait_for(std::chrono::milliseconds(wait ? kOpenPollMs : 0)) != std::future_status::ready) {
        request_redraw();  // the "opening..." line counts up
        return;
    }
    std::shared_ptr<Opened> opened;  // null: the worker could not even say why (out of memory)
    try {
        opened = open_job_.get();
    } catch (...) {
    }
    const std::string path = std::exchange(open_job_path_, std::string());
    const bool cancelled = open_cancel_->load();
    open_cancel_.reset();
    request_redraw();
    if (cancelled) {
        message_ = "opening " + path + " cancelled";
        message_is_error_ = false;
        log_.add("open_cancelled", {{"path", path}});
        return;
    }
    if (!opened || !opened->error.empty()) {
        fail(opened ? opened->error : "cannot open " + path + ": out of memory");
        return;
    }
    halt_run();
    autosave_->at_exit();  // the previous image's unsaved work
    report_autosave();
    session_ = std::move(opened->session);
    image_path_ = path;
    config_.roi_path = opened->brain_roi ? "auto" : "none";  // the default's choice, or --roi none
    config_.roi_by_default = opened->brain_roi;
    config_.image_corrected = opened->corrected;
    config_.image_oriented = opened->oriented;
    image_name_ = std::filesystem::path(path).filename().string();
    attach_session();
    message_ = "opened " + path + (opened->brain_roi ? ", the front bounded by the automatic brain mask" : "") +
               (opened->bias_skipped.empty() ? "" : " (" + opened->bias_skipped + ")") +
               (opened->no_brain.empty() ? "" : "; " + opened->no_brain) +
               (opened->no_data.empty() ? "" : "; " + opened->no_data);
    message_is_error_ = false;
    log_.add("open", {{"path", path}, {"bias_corrected", opened->corrected}, {"roi", config_.roi_path}});
}

}  // namespace liveset::viewer
