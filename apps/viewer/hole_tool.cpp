// The viewer's hole finder: a worker-thread scan of a copied segmentation (hole_tool.hpp).
#include "hole_tool.hpp"
#include "liveset/base/stopwatch.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace liveset::viewer {

namespace {

const std::vector<HoleCandidate> kNoHoles;

}  // namespace

HoleTool::~HoleTool() { reset(); }

void HoleTool::reset() {
    if (job_.valid()) job_.wait();
    job_ = {};
    image_.reset();
    roi_.reset();
    region_.reset();
    session_ = nullptr;
    scan_.reset();
    verdicts_.clear();
    error_.clear();
    selected_.reset();
    aimed_.clear();
    job_sites_.clear();
}

bool HoleTool::start(const Session& session, const HoleScanOptions& options) {
    if (job_.valid()) return false;
    options.validate();
    const SheetFit session_fit = session.sheet_fit();
    if (session_ != &session || !image_) {  // the image, ROI and model region never change within a session: copy them once
        image_ = std::make_shared<const Grid<float>>(session.image());
        roi_ = session.roi() ? std::make_shared<const Grid<std::uint8_t>>(*session.roi()) : nullptr;
        region_ = session_fit.region ? std::make_shared<const Grid<std::uint8_t>>(*session_fit.region) : nullptr;
        session_ = &session;
    }
    Grid<std::uint8_t> mask = session.mask();  // φ < 0 within the ROI, copied on this thread
    std::shared_ptr<const HoleScan> before = scan_ ? std::make_shared<const HoleScan>(*scan_) : nullptr;
    job_sites_ = aimed_;
    job_revision_ = session.revision();
    started_ = std::chrono::steady_clock::now();
    SheetFit fit = session_fit;  // the band from where the session's tissue model was fitted, in the copy
    fit.region = region_.get();
    job_ = std::async(std::launch::async, [image = image_, roi = roi_, region = region_, mask = std::move(mask), options, fit, before,
                                           sites = job_sites_]() {
        Result r;
        try {
            r.scan = scan_holes(std::move(mask), *image, roi.get(), options, fit);
            if (before && !sites.empty()) {
                const std::vector<HoleVerdict> v = hole_verdicts(sites, *before, *r.scan, *image, roi.get());
                for (std::size_t k = 0; k < sites.size(); ++k) r.verdicts.push_back({sites[k], v[k]});
            }
        } catch (const std::exception& e) {
            r.error = e.what();
        }
        return r;
    });
    return true;
}

double HoleTool::running_ms() const {
    if (!job_.valid()) return 0.0;
    return ms_since(started_);
}

bool HoleTool::poll(std::chrono::milliseconds wait) {
    if (!job_.valid() || job_.wait_for(wait) != std::future_status::ready) return false;
    Result r = job_.get();
    job_ = {};
    error_ = r.error;
    if (!r.scan) return true;  // failed: the previous list stays
    scan_ = std::move(r.scan);
    revision_ = job_revision_;
    verdicts_ = std::move(r.verdicts);
    // The sites judged now are done with; any aimed at while the scan ran wait for the next one.
    aimed_.erase(aimed_.begin(), aimed_.begin() + static_cast<std::ptrdiff_t>(std::min(job_sites_.size(), aimed_.size())));
    job_sites_.clear();
    selected_.reset();
    return true;
}

const std::vector<HoleCandidate>& HoleTool::holes() const { return scan_ ? scan_->holes : kNoHoles; }

void HoleTool::aimed_at(Vec3d site) {
    for (const Vec3d& s : aimed_)
        if (s == site) return;
    aimed_.push_back(site);
}

nlohmann::json hole_report(const HoleTool& tool) {
    const auto triple = [](Vec3i v) { return nlohmann::json{v.x, v.y, v.z}; };
    nlohmann::json sites = nlohmann::json::array(), verdicts = nlohmann::json::array();
    std::size_t voxels = 0;
    const std::vector<HoleCandidate>& holes = tool.holes();
    for (std::size_t k = 0; k < holes.size(); ++k) {
        const HoleCandidate& h = holes[k];
        voxels += h.voxels;
        sites.push_back({{"rank", k + 1}, {"voxels", h.voxels}, {"rim", h.rim}, {"target", triple(h.site)},
                         {"voxel1", triple(h.site + Vec3i{1, 1, 1})}, {"kind", "gap"}});
    }
    for (const SiteVerdict& v : tool.verdicts()) {
        const Vec3i c{static_cast<int>(std::lround(v.site.x)), static_cast<int>(std::lround(v.site.y)), static_cast<int>(std::lround(v.site.z))};
        verdicts.push_back({{"target", triple(c)}, {"before", v.verdict.before}, {"after", v.verdict.after},
                            {"closed", v.verdict.closed && v.verdict.before > 0}, {"genus_before", v.verdict.genus_before},
                            {"genus_after", v.verdict.genus_after}});
    }
    nlohmann::json j{{"count", holes.size()}, {"voxels", voxels}, {"sites", sites}, {"verdicts", verdicts}, {"verdict_radius", kHoleVerdictRadius}};
    if (const auto& s = tool.scan()) {
        j["ms"] = s->ms;
        j["sheet_band"] = {s->finder.sheet_lower, s->finder.sheet_upper};
        j["band_from"] = s->band_from;
        j["min_voxels"] = s->finder.min_voxels;
        j["warnings"] = s->warnings;
    }
    return j;
}

}  // namespace liveset::viewer
