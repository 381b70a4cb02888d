// Frame budget decisions: steps per frame, redraw pacing while running, level of detail.
#include "frame_budget.hpp"

#include <cmath>
#include <stdexcept>

namespace liveset::viewer {

namespace {

// Running average: quick to follow a change of cost (the surface grows), robust to one outlier.
double blend(double average, double sample, bool known) { return known ? 0.75 * average + 0.25 * sample : sample; }

bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

void FrameBudgetOptions::validate() const {
    if (!finite_positive(frame_ms)) throw std::invalid_argument("frame budget: frame_ms must be positive");
    if (!finite_positive(draw_share) || draw_share > 1.0) throw std::invalid_argument("frame budget: draw_share must be in (0, 1]");
    if (!std::isfinite(still_ms) || still_ms < 0.0) throw std::invalid_argument("frame budget: still_ms must be >= 0");
    if (!std::isfinite(lod_above_ms) || lod_above_ms < 0.0) throw std::invalid_argument("frame budget: lod_above_ms must be >= 0");
    if (lod_factor < 2 || lod_factor > 8) throw std::invalid_argument("frame budget: lod_factor must be 2 to 8");
    if (!finite_positive(handover_ms)) throw std::invalid_argument("frame budget: handover_ms must be positive");
}

FrameBudget::FrameBudget(const FrameBudgetOptions& options) : options_(options) { options_.validate(); }

bool FrameBudget::another_step(int steps_taken, double elapsed_ms) const {
    if (steps_taken <= 0) return true;  // work always advances
    return elapsed_ms + step_ms_ + upload_ms_ <= options_.frame_ms;
}

void FrameBudget::record_step(double ms) {
    step_ms_ = blend(step_ms_, ms, step_known_);
    step_known_ = true;
}

void FrameBudget::record_upload(double ms) {
    upload_ms_ = blend(upload_ms_, ms, upload_known_);
    upload_known_ = true;
}

bool FrameBudget::redraw_due(double now_ms) const {
    if (!redrawn_) return true;
    return now_ms - last_redraw_ms_ >= redraw_cost_ms_ * (1.0 / options_.draw_share - 1.0);
}

void FrameBudget::record_redraw(double now_ms, double cost_ms) {
    last_redraw_ms_ = now_ms;
    redraw_cost_ms_ = cost_ms;
    redrawn_ = true;
}

void FrameBudget::record_full_draw(double ms) {
    full_draw_ms_ = blend(full_draw_ms_, ms, full_draw_known_);
    full_draw_known_ = true;
}

bool FrameBudget::coarse(double now_ms, bool busy) const {
    if (!full_draw_known_ || full_draw_ms_ <= options_.lod_above_ms) return false;
    return busy || (has_input_ && now_ms - last_input_ms_ < options_.still_ms);
}

}  // namespace liveset::viewer
