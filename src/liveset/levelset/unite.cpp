// SparseField::unite_in_box: the union with a shape (a seed ball) re-initialised locally, at the
// cost of the shape's neighbourhood instead of the lattice.
#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "liveset/levelset/band_detail.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

using namespace detail;

ChangedPoints SparseField::unite_in_box(Vec3i lo, Vec3i hi, const std::function<double(Vec3d)>& sdf) {
    const auto start = std::chrono::steady_clock::now();
    const Vec3i d = lattice().dims();
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(lo[a], 0);
        hi[a] = std::min(hi[a], d[a] - 1);
    }
    const double far = layers_ + 1.0;
    // 1. The values init_from_sdf(min(φ, sdf)) would give, where they differ from φ (checked
    //    before anything changes: a throw leaves the field as it was).
    std::unordered_map<PointIndex, float> value;
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                const double s = sdf(Vec3d{static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)});
                if (!std::isfinite(s))
                    throw std::invalid_argument("the shape's signed distance is not finite at voxel (" + std::to_string(x) + ", " +
                                                std::to_string(y) + ", " + std::to_string(z) + ")");
                const PointIndex i = lattice().index({x, y, z});
                const auto v = static_cast<float>(std::clamp(std::min(static_cast<double>(phi_[i]), s), -far, far));
                if (std::bit_cast<std::uint32_t>(v) != std::bit_cast<std::uint32_t>(phi_[i])) value.emplace(i, v);
            }
    if (value.empty()) return {{}, std::vector<PointIndex>{}};
    const auto v_at = [&](PointIndex i) {
        const auto it = value.find(i);
        return it == value.end() ? phi_[i] : it->second;
    };
    // 2. init_from_sdf's pull of opposite-sign far neighbours onto the zero layer. In a valid field
    //    no such pair exists away from the changed values, so their 6-neighbourhoods suffice.
    std::vector<PointIndex> candidates;
    for (const auto& [i, v] : value) {
        candidates.push_back(i);
        for_each_neighbor6(lattice(), decoder_, i, [&](PointIndex q) { candidates.push_back(q); });
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    std::vector<std::pair<PointIndex, float>> pulled;
    for (PointIndex i : candidates) {
        const float v = v_at(i);
        if (std::abs(v) <= 0.5f) continue;
        bool opposite = false;
        for_each_neighbor6(lattice(), decoder_, i, [&](PointIndex q) {
            const float w = v_at(q);
            if (std::abs(w) > 0.5f && ((w < 0) != (v < 0))) opposite = true;
        });
        if (opposite) pulled.emplace_back(i, v < 0 ? -0.5f : 0.5f);
    }
    for (const auto& [i, v] : pulled) value[i] = v;
    // 3. Re-layer the Manhattan N-ball of every changed value: a point farther than N from all of
    //    them keeps its layer and value (they depend only on the zero layer within N).
    std::vector<PointIndex> changed_values;
    changed_values.reserve(value.size());
    for (const auto& [i, v] : value) changed_values.push_back(i);
    std::sort(changed_values.begin(), changed_values.end());  // a fixed order, whatever the hashing
    std::vector<RegionPoint> region;
    for (PointIndex i : changed_values) collect_ball(i, region);
    for (PointIndex i : changed_values) {
        const float v = value[i];
        phi_[i] = v;
        status_[i] = std::abs(v) <= 0.5f ? kPendZero : (v < 0 ? kPendNeg : kPendPos);
    }
    sweep_layers(region);
    ChangedPoints changed = finish(region);
    activity_.wake_near(changed.points, lattice(), steps_);
    last_update_ms_ = ms_since(start);
    return changed;
}

}  // namespace liveset
