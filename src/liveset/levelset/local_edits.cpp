// SparseField's local edits and undo: edits of zero-layer values (applied through the shared
// repair, sparse_field.cpp) and the write-back of recorded point states.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

using detail::point_text;

ChangedPoints SparseField::apply_edits(std::span<const ZeroLayerEdit> edits, RepairScope scope) {
    std::vector<ZeroLayerEdit> merged(edits.begin(), edits.end());
    std::sort(merged.begin(), merged.end(), [](const auto& a, const auto& b) { return a.point < b.point; });
    std::size_t out = 0;
    for (std::size_t n = 0; n < merged.size(); ++n) {
        const ZeroLayerEdit& e = merged[n];
        if (e.point >= phi_.size()) throw std::invalid_argument("edit outside the lattice");
        if (!std::isfinite(e.delta))
            throw std::invalid_argument("edit at " + point_text(lattice(), e.point) + " has a non-finite change");
        if (status_[e.point] != 0)
            throw std::invalid_argument("edit at " + point_text(lattice(), e.point) + " is not on the zero layer");
        if (out > 0 && merged[out - 1].point == e.point)
            merged[out - 1].delta += e.delta;
        else
            merged[out++] = e;
    }
    merged.resize(out);
    for (auto& e : merged) e.delta = std::clamp(e.delta, -0.5f, 0.5f);
    ChangedPoints changed = commit(merged, scope);
    activity_.wake_near(changed.points, lattice(), steps_);  // an edit wakes the front around it
    return changed;
}

ChangedPoints SparseField::apply_in_box(Vec3i lo, Vec3i hi, const std::function<float(Vec3i, float)>& delta) {
    const Vec3i d = lattice().dims();
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(lo[a], 0);
        hi[a] = std::min(hi[a], d[a] - 1);
    }
    std::vector<ZeroLayerEdit> edits;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                const PointIndex i = lattice().index({x, y, z});
                if (status_[i] != 0) continue;
                const float dv = delta({x, y, z}, phi_[i]);
                if (dv != 0.0f) edits.push_back({i, dv});
            }
    return apply_edits(edits, RepairScope::kLocal);
}

ChangedPoints SparseField::restore(std::span<const PointState> states) {
    const auto start = std::chrono::steady_clock::now();
    for (const PointState& s : states) {
        if (s.point >= phi_.size()) throw std::invalid_argument("restored point outside the lattice");
        if (s.status < far_inside() || s.status > far_outside())
            throw std::invalid_argument("restored status at " + point_text(lattice(), s.point) + " is out of range");
        if (!std::isfinite(s.phi)) throw std::invalid_argument("restored value at " + point_text(lattice(), s.point) + " is not finite");
    }
    ensure_slots();  // list_add and list_remove use them
    ChangedPoints changed;
    changed.sign_changes.emplace();
    for (const PointState& s : states) {
        const PointIndex i = s.point;
        const std::int8_t old = status_[i];
        const bool value_changed = std::bit_cast<std::uint32_t>(phi_[i]) != std::bit_cast<std::uint32_t>(s.phi);
        if (old == s.status && !value_changed) continue;
        if (old != s.status) {
            if (old >= -layers_ && old <= layers_) list_remove(i, old);
            if (s.status >= -layers_ && s.status <= layers_) list_add(i, s.status);
            status_[i] = s.status;
        }
        if ((phi_[i] < 0.0f) != (s.phi < 0.0f)) changed.sign_changes->push_back(i);
        phi_[i] = s.phi;
        changed.points.push_back(i);
    }
    activity_.wake_near(changed.points, lattice(), steps_);  // so does an undo
    last_update_ms_ = ms_since(start);
    return changed;
}

}  // namespace liveset
