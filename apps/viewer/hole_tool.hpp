// The viewer's hole finder (issue 18): runs the truth-free finder (session/hole_scan.hpp) on a copy
// of the session's segmentation on a worker thread, so the window keeps drawing; keeps the ranked
// candidates, the selected one, the sites the swarm was aimed at since the last scan and - when a
// scan follows a repair - the finder's verdict on each of them (closed or open, as `liveset
// repair` reports). No ImGui, no OpenGL: the panel and the markers are in viewer_holes.cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <future>
#include <nlohmann/json.hpp>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "liveset/session/hole_scan.hpp"
#include "liveset/session/session.hpp"

namespace liveset::viewer {

// The finder's verdict on one site the swarm was aimed at before this scan.
struct SiteVerdict {
    Vec3d site;
    HoleVerdict verdict;
};

class HoleTool {
public:
    HoleTool() = default;
    ~HoleTool();  // waits for a running scan
    HoleTool(const HoleTool&) = delete;
    HoleTool& operator=(const HoleTool&) = delete;

    // Starts a scan of the session's current segmentation (copied here, on the caller's thread).
    // False (nothing started) while a scan runs. Bad options throw std::invalid_argument.
    bool start(const Session& session, const HoleScanOptions& options);
    bool running() const { return job_.valid(); }
    double running_ms() const;  // since start() (0 when idle)
    // Takes a finished scan, waiting up to `wait` for it: true when one finished now (the list,
    // the selection and the verdicts are new; error() says why when it failed).
    bool poll(std::chrono::milliseconds wait = std::chrono::milliseconds(0));
    // Forgets everything (a new image); waits for a running scan.
    void reset();

    const std::optional<HoleScan>& scan() const { return scan_; }
    const std::vector<HoleCandidate>& holes() const;  // of the last scan, largest first
    std::uint64_t scanned_revision() const { return revision_; }  // the session's revision it scanned
    void still_current(std::uint64_t revision) { revision_ = revision; }  // a change that left φ as scanned
    const std::string& error() const { return error_; }
    const std::vector<SiteVerdict>& verdicts() const { return verdicts_; }

    std::optional<std::size_t> selected() const { return selected_; }  // 0-based into holes()
    void select(std::optional<std::size_t> k) { selected_ = k; }
    // The swarm was aimed at `site` (from the list or a click): the next scan judges it.
    void aimed_at(Vec3d site);
    const std::vector<Vec3d>& aimed() const { return aimed_; }

private:
    struct Result {
        std::optional<HoleScan> scan;
        std::vector<SiteVerdict> verdicts;
        std::string error;
    };

    std::shared_ptr<const Grid<float>> image_;  // the session's image, copied once per image
    std::shared_ptr<const Grid<std::uint8_t>> roi_;
    std::shared_ptr<const Grid<std::uint8_t>> region_;  // the session's model region (Session::sheet_fit), copied with them
    const Session* session_ = nullptr;
    std::future<Result> job_;
    std::chrono::steady_clock::time_point started_;
    std::uint64_t job_revision_ = 0, revision_ = 0;
    std::vector<Vec3d> job_sites_;  // aimed at before the running scan: judged by it
    std::optional<HoleScan> scan_;
    std::vector<SiteVerdict> verdicts_;
    std::string error_;
    std::optional<std::size_t> selected_;
    std::vector<Vec3d> aimed_;
};

// The last scan as a script prints it: count, voxels, ms, band, sites [{rank, voxels, rim, target
// (0-based, as --target), voxel1 (1-based, as the cursor), kind}], verdicts [{target, before,
// after, closed, genus_before, genus_after}].
nlohmann::json hole_report(const HoleTool& tool);

}  // namespace liveset::viewer
