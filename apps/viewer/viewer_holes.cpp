// The hole finder in the viewer (issue 18): the panel's Holes section (Find holes, the ranked list,
// Previous / Next, Repair, the verdicts after a repair), selecting a candidate (the cursor moves to
// its site in all three slices and the swarm is aimed there, as a clicked target), and the markers
// (rings with the rank in the slice panes, points in the 3D pane). The scan runs on a worker
// thread (hole_tool.hpp); the window keeps drawing and shows "finding...".
#include <fmt/core.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "viewer.hpp"

namespace liveset::viewer {

namespace {

constexpr int kMarkerSlices = 2;  // a site this many slices off the shown one is still marked (dashed)
constexpr int kPollWaitMs = 40;   // a frame waits this long for a running scan (the window's pace meanwhile)

nlohmann::json triple(Vec3i v) { return {v.x, v.y, v.z}; }

Vec3i rounded(Vec3d v) {
    return {static_cast<int>(std::lround(v.x)), static_cast<int>(std::lround(v.y)), static_cast<int>(std::lround(v.z))};
}

const char* verdict_word(const HoleVerdict& v) { return v.before == 0 ? "no hole there" : (v.closed ? "closed" : "open"); }

}  // namespace

bool Viewer::find_holes(const HoleScanOptions& options) {
    if (!session_) return fail("open an image first");
    if (holes_.running()) return fail("the hole finder is still running");
    if (!session_->has_surface()) return fail("no segmentation to search: place seeds and run, or load a mask");
    try {
        holes_.start(*session_, options);
    } catch (const std::invalid_argument& e) {
        return fail(e.what());
    }
    message_ = "finding holes...";
    message_is_error_ = false;
    log_.add("find_holes", {{"min_voxels", options.min_voxels}});
    request_redraw();
    return true;
}

void Viewer::poll_holes(bool wait) {
    if (!holes_.running()) return;
    if (!holes_.poll(std::chrono::milliseconds(wait ? kPollWaitMs : 0))) {
        request_redraw();  // the "finding..." line counts up
        return;
    }
    hole_rows_logged_.clear();
    mark_all_panes();
    if (!holes_.error().empty()) {
        fail(holes_.error());
        return;
    }
    const HoleScan& s = *holes_.scan();
    std::size_t voxels = 0;
    for (const HoleCandidate& h : s.holes) voxels += h.voxels;
    message_ = fmt::format("{} candidate hole(s) of >= {} voxels ({} voxels) in {:.2f} s", s.holes.size(), s.finder.min_voxels, voxels,
                           s.ms / 1000.0);
    message_is_error_ = false;
    nlohmann::json verdicts = nlohmann::json::array();
    for (const SiteVerdict& v : holes_.verdicts())
        verdicts.push_back({{"target", triple(rounded(v.site))}, {"before", v.verdict.before}, {"after", v.verdict.after},
                            {"closed", v.verdict.closed && v.verdict.before > 0}});
    log_.add("holes", {{"count", s.holes.size()}, {"voxels", voxels}, {"ms", s.ms}, {"verdicts", verdicts}});
}

bool Viewer::select_hole(std::size_t rank) {
    if (!session_) return fail("open an image first");
    const std::vector<HoleCandidate>& holes = holes_.holes();
    if (rank < 1 || rank > holes.size())
        return fail(holes.empty() ? "no hole candidates: Find holes first" : fmt::format("no hole {}: the list has {}", rank, holes.size()));
    holes_.select(rank - 1);
    const Vec3i site = holes[rank - 1].site;
    set_cursor(site);
    // A zoomed slice pane follows the cursor (ITK-SNAP keeps the cursor in view).
    for (int i = 0; i < 3; ++i)
        if (slices_.panes[static_cast<std::size_t>(i)].zoom > 1.0)
            slices_.panes[static_cast<std::size_t>(i)].centre_uv = slice_viewport(static_cast<Pane>(i), 1, 1).geometry.to_uv(site.cast<double>());
    log_cursor("hole");
    mark_all_panes();
    log_.add("select_hole", {{"rank", rank}, {"site", triple(site)}, {"voxels", holes[rank - 1].voxels}});
    const std::string what = fmt::format("hole {} of {}: {} voxels at ({}, {}, {})", rank, holes.size(), holes[rank - 1].voxels, site.x + 1,
                                         site.y + 1, site.z + 1);
    const bool current = session_->revision() == holes_.scanned_revision();
    if (!set_target(site.cast<double>())) return fail(what + ": " + message_);
    if (current) holes_.still_current(session_->revision());  // only the target moved: the list still holds
    message_ = what + ", the swarm's target";
    return true;
}

void Viewer::step_hole(int delta) {
    const std::size_t n = holes_.holes().size();
    if (n == 0) {
        fail("no hole candidates: Find holes first");
        return;
    }
    const auto k = static_cast<long>(holes_.selected().value_or(delta > 0 ? n - 1 : 0));
    const long next = ((k + delta) % static_cast<long>(n) + static_cast<long>(n)) % static_cast<long>(n);
    select_hole(static_cast<std::size_t>(next) + 1);
}

// The candidates near the shown slice: a ring and the rank; the selected one highlighted.
std::vector<render::SliceMarker> Viewer::hole_markers(const render::SliceGeometry& g, int slice) const {
    std::vector<render::SliceMarker> out;
    const std::vector<HoleCandidate>& holes = holes_.holes();
    for (std::size_t k = 0; k < holes.size(); ++k) {
        const Vec3d p = holes[k].site.cast<double>();
        const int off = std::abs(static_cast<int>(std::lround(p[g.normal_axis])) - slice);
        if (off > kMarkerSlices) continue;
        out.push_back({g.to_uv(p), static_cast<int>(k + 1), holes_.selected() == k, off == 0});
    }
    return out;
}

void Viewer::add_hole_markers(render::SceneContent& c) {
    hole_points_.clear();
    const std::vector<HoleCandidate>& holes = holes_.holes();
    for (std::size_t k = 0; k < holes.size(); ++k) {
        const glm::vec3 p(static_cast<float>(holes[k].site.x), static_cast<float>(holes[k].site.y), static_cast<float>(holes[k].site.z));
        if (holes_.selected() == k) c.selected_marker = p;
        else hole_points_.push_back(p);
    }
    c.markers = hole_points_;
}

// The ranked list: rank, size, site (1-based, as the cursor), kind; a click selects.
void Viewer::draw_hole_list() {
    const std::vector<HoleCandidate>& holes = holes_.holes();
    const float rows = static_cast<float>(std::min<std::size_t>(holes.size(), 8) + 1);
    const ImGuiTableFlags flags = ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV | ImGuiTableFlags_ScrollY | ImGuiTableFlags_SizingFixedFit;
    if (!ImGui::BeginTable("holes", 4, flags, ImVec2(0.0f, rows * ImGui::GetTextLineHeightWithSpacing() + 4.0f))) return;
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("#", ImGuiTableColumnFlags_WidthFixed, 24.0f);
    ImGui::TableSetupColumn("voxels", ImGuiTableColumnFlags_WidthFixed, 56.0f);
    ImGui::TableSetupColumn("site (1-based)", ImGuiTableColumnFlags_WidthStretch);
    ImGui::TableSetupColumn("kind", ImGuiTableColumnFlags_WidthFixed, 30.0f);
    ImGui::TableHeadersRow();
    nlohmann::json rects = nlohmann::json::object();
    for (std::size_t k = 0; k < holes.size(); ++k) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        const bool selected = holes_.selected() == k;
        const std::string label = fmt::format("{}##hole{}", k + 1, k + 1);
        if (ImGui::Selectable(label.c_str(), selected, ImGuiSelectableFlags_SpanAllColumns)) {
            log_.add("button", {{"name", fmt::format("hole_{}", k + 1)}});
            select_hole(k + 1);
        }
        if (k < 8) {  // where a driving test clicks
            const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
            rects[fmt::format("hole_{}", k + 1)] = {static_cast<int>(lo.x), static_cast<int>(lo.y), static_cast<int>(hi.x - lo.x),
                                                    static_cast<int>(hi.y - lo.y)};
        }
        const Vec3i s = holes[k].site;
        ImGui::TableNextColumn();
        ImGui::Text("%zu", holes[k].voxels);
        ImGui::TableNextColumn();
        ImGui::Text("%d, %d, %d", s.x + 1, s.y + 1, s.z + 1);
        ImGui::TableNextColumn();
        ImGui::TextUnformatted("gap");
    }
    ImGui::EndTable();
    // Logged again whenever the rows move (a scroll bar appearing re-wraps the text above them).
    if (!holes.empty() && rects.dump() != hole_rows_logged_) {
        hole_rows_logged_ = rects.dump();
        log_.add("hole_rows", {{"rows", rects}});
    }
}

// Find holes, the list, Previous / Next / Repair, and the verdicts on the sites repaired before.
void Viewer::draw_holes_section() {
    ImGui::BeginDisabled(holes_.running());
    if (panel_button("Find holes", "find_holes")) find_holes(ui_holes_);
    ImGui::EndDisabled();
    ImGui::SameLine();
    int min_voxels = static_cast<int>(ui_holes_.min_voxels);
    ImGui::SetNextItemWidth(80.0f);
    if (ImGui::InputInt("min voxels", &min_voxels, 0, 0)) ui_holes_.min_voxels = static_cast<std::size_t>(std::max(min_voxels, 1));
    help_marker("candidate holes of the segmented sheet without ground truth (liveset holes): gaps of sheet-like voxels "
                "where the tissue the sheet encloses meets the outside; the band from the tissue model. Largest first; "
                "a click (or N / P) moves the cursor there and aims the swarm at it; Repair runs the swarm; Find holes "
                "again says whether the repaired sites closed.");
    if (holes_.running()) {
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "finding... %.1f s", holes_.running_ms() / 1000.0);
        return;
    }
    if (!holes_.scan()) {
        ImGui::TextDisabled("not searched yet");
        return;
    }
    const HoleScan& s = *holes_.scan();
    ImGui::Text("%zu candidate(s) in %.2f s", s.holes.size(), s.ms / 1000.0);
    ImGui::TextDisabled("band [%.4g, %.4g) from the %s", s.finder.sheet_lower, s.finder.sheet_upper, s.band_from.c_str());
    if (session_->revision() != holes_.scanned_revision()) ImGui::TextDisabled("(the segmentation changed since: Find holes again)");
    draw_hole_list();
    ImGui::BeginDisabled(s.holes.empty());
    if (panel_button("Previous (P)", "previous_hole")) step_hole(-1);
    ImGui::SameLine();
    if (panel_button("Next (N)", "next_hole")) step_hole(1);
    ImGui::SameLine();
    ImGui::BeginDisabled(!holes_.selected());
    if (panel_button(swarm_running_ ? "Stop repair" : "Repair", "repair_hole")) set_swarm_running(!swarm_running_);
    ImGui::EndDisabled();
    ImGui::EndDisabled();
    for (const SiteVerdict& v : holes_.verdicts()) {
        const Vec3i c = rounded(v.site);
        ImGui::TextWrapped("repaired (%d, %d, %d): %zu -> %zu hole voxels within %.0f: %s", c.x + 1, c.y + 1, c.z + 1, v.verdict.before,
                           v.verdict.after, kHoleVerdictRadius, verdict_word(v.verdict));
    }
}

}  // namespace liveset::viewer
