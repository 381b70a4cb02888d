// Perforations of a segmented shell: missed-truth regions joining the inner tissue to the outside.
#include "liveset/eval/perforations.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "liveset/eval/topology.hpp"
#include "liveset/grid/digital_topology.hpp"

namespace liveset {

namespace {

// Fills each region's `nearest` (its voxel nearest its centroid; slot maps a component label to
// its index in `out`) and sorts the regions largest first, ties by centroid (deterministic).
void locate_nearest(const Lattice& lat, const ComponentLabels& label, const std::vector<std::size_t>& slot,
                    std::vector<Perforation>& out) {
    std::vector<double> best(out.size(), 1e300);
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::size_t j = slot[label[i]];
        if (j == SIZE_MAX) continue;
        const Vec3d d = lat.coord(i).cast<double>() - out[j].centroid;
        if (dot(d, d) < best[j]) {
            best[j] = dot(d, d);
            out[j].nearest = lat.coord(i);
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const Perforation& a, const Perforation& b) {
        if (a.voxels != b.voxels) return a.voxels > b.voxels;
        if (a.centroid.z != b.centroid.z) return a.centroid.z < b.centroid.z;
        if (a.centroid.y != b.centroid.y) return a.centroid.y < b.centroid.y;
        return a.centroid.x < b.centroid.x;
    });
}

// The 6-connected components of the truth the mask missed (labels 1..count, 0 elsewhere).
ComponentLabels label_missed(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth, std::size_t& count) {
    Grid<std::uint8_t> missed(mask.lattice(), 0);
    for (PointIndex i = 0; i < missed.size(); ++i) missed[i] = truth[i] && !mask[i];
    count = 0;
    return label_components(missed, 6, &count);
}

// Each labelled region's size, coordinate sum and bounding box (index k = label; 0 unused).
struct RegionBoxes {
    std::vector<std::size_t> size;
    std::vector<Vec3d> sum;
    std::vector<Vec3i> lo, hi;
    Vec3d centroid(std::uint32_t k) const { return sum[k] / static_cast<double>(size[k]); }
};

RegionBoxes region_boxes(const Lattice& lat, const ComponentLabels& label, std::size_t count) {
    RegionBoxes r{std::vector<std::size_t>(count + 1, 0), std::vector<Vec3d>(count + 1, Vec3d{0, 0, 0}),
                  std::vector<Vec3i>(count + 1, lat.dims()), std::vector<Vec3i>(count + 1, Vec3i{-1, -1, -1})};
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = label[i];
        if (!k) continue;
        const Vec3i c = lat.coord(i);
        ++r.size[k];
        r.sum[k] += c.cast<double>();
        r.lo[k] = {std::min(r.lo[k].x, c.x), std::min(r.lo[k].y, c.y), std::min(r.lo[k].z, c.z)};
        r.hi[k] = {std::max(r.hi[k].x, c.x), std::max(r.hi[k].y, c.y), std::max(r.hi[k].z, c.z)};
    }
    return r;
}

}  // namespace

std::vector<Perforation> find_perforations(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth,
                                           const Grid<std::uint8_t>& inner) {
    if (!(mask.dims() == truth.dims()) || !(mask.dims() == inner.dims()))
        throw std::invalid_argument("find_perforations: mask, truth and inner differ in size");
    const Lattice& lat = mask.lattice();
    std::size_t count = 0;
    const ComponentLabels label = label_missed(mask, truth, count);
    std::vector<std::size_t> size(count + 1, 0);
    std::vector<Vec3d> sum(count + 1, Vec3d{0, 0, 0});
    std::vector<std::uint8_t> touches_inner(count + 1, 0), touches_outer(count + 1, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = label[i];
        if (!k) continue;
        const Vec3i c = lat.coord(i);
        ++size[k];
        sum[k] += c.cast<double>();
        for (int f = 0; f < 6; ++f) {
            Vec3i q = c;
            q[f / 2] += (f % 2) ? 1 : -1;
            if (!lat.contains(q)) {
                touches_outer[k] = 1;
                continue;
            }
            if (mask(q) || truth(q)) continue;
            if (inner(q))
                touches_inner[k] = 1;
            else
                touches_outer[k] = 1;
        }
    }
    std::vector<Perforation> out;
    std::vector<std::size_t> slot(count + 1, SIZE_MAX);  // component label -> index in out
    for (std::uint32_t k = 1; k <= count; ++k)
        if (touches_inner[k] && touches_outer[k]) {
            slot[k] = out.size();
            out.push_back({size[k], sum[k] / static_cast<double>(size[k]), Vec3i{0, 0, 0}});
        }
    locate_nearest(lat, label, slot, out);
    return out;
}

std::vector<Perforation> find_cavities(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner) {
    if (!(mask.dims() == inner.dims())) throw std::invalid_argument("find_cavities: mask and inner differ in size");
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    Grid<std::uint8_t> outside(lat, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) outside[i] = !mask[i];
    std::size_t count = 0;
    const ComponentLabels label = label_components(outside, 6, &count);
    std::vector<std::size_t> size(count + 1, 0);
    std::vector<Vec3d> sum(count + 1, Vec3d{0, 0, 0});
    std::vector<std::uint8_t> open(count + 1, 0);  // touches the border or the inner core
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = label[i];
        if (!k) continue;
        const Vec3i c = lat.coord(i);
        ++size[k];
        sum[k] += c.cast<double>();
        if (inner[i] || c.x == 0 || c.y == 0 || c.z == 0 || c.x == d.x - 1 || c.y == d.y - 1 || c.z == d.z - 1) open[k] = 1;
    }
    std::vector<Perforation> out;
    std::vector<std::size_t> slot(count + 1, SIZE_MAX);
    for (std::uint32_t k = 1; k <= count; ++k)
        if (!open[k]) {
            slot[k] = out.size();
            out.push_back({size[k], sum[k] / static_cast<double>(size[k]), Vec3i{0, 0, 0}});
        }
    locate_nearest(lat, label, slot, out);
    return out;
}

std::vector<Perforation> find_missed_tunnels(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth) {
    if (!(mask.dims() == truth.dims())) throw std::invalid_argument("find_missed_tunnels: mask and truth differ in size");
    const Lattice& lat = mask.lattice();
    std::size_t count = 0;
    const ComponentLabels label = label_missed(mask, truth, count);
    const RegionBoxes r = region_boxes(lat, label, count);
    std::vector<Perforation> out;
    std::vector<std::size_t> slot(count + 1, SIZE_MAX);
    for (std::uint32_t k = 1; k <= count; ++k) {
        // χ over the region's box one voxel wider, without and with the region: a rise is a tunnel
        // (or a cavity, which find_cavities reports) that filling it closes.
        const Vec3i a = r.lo[k] - Vec3i{1, 1, 1}, b = r.hi[k] + Vec3i{1, 1, 1};
        const auto in_mask = [&](Vec3i q) { return lat.contains(q) && mask(q) != 0; };
        const auto in_filled = [&](Vec3i q) { return lat.contains(q) && (mask(q) != 0 || label[lat.index(q)] == k); };
        if (euler_characteristic_26(in_filled, a, b) <= euler_characteristic_26(in_mask, a, b)) continue;
        slot[k] = out.size();
        out.push_back({r.size[k], r.centroid(k), Vec3i{0, 0, 0}});
    }
    locate_nearest(lat, label, slot, out);
    return out;
}

std::vector<Perforation> find_inner_handles(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner) {
    if (!(mask.dims() == inner.dims())) throw std::invalid_argument("find_inner_handles: mask and inner differ in size");
    const Lattice& lat = mask.lattice();
    Grid<std::uint8_t> taken(lat, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) taken[i] = mask[i] && inner[i];
    std::size_t count = 0;
    const ComponentLabels label = label_components(taken, 26, &count);
    const RegionBoxes r = region_boxes(lat, label, count);
    // Whether a region has a face neighbour outside the mask (or the lattice): one without is
    // enclosed by the mask, and removing it opens a cavity (no handle cut; skipped before the
    // whole-mask count).
    std::vector<std::uint8_t> faces_out(count + 1, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = label[i];
        if (!k) continue;
        const Vec3i c = lat.coord(i);
        for (int f = 0; f < 6 && !faces_out[k]; ++f) {
            Vec3i q = c;
            q[f / 2] += (f % 2) ? 1 : -1;
            faces_out[k] = !lat.contains(q) || !mask(q);
        }
    }
    std::vector<Perforation> out;
    std::vector<std::size_t> slot(count + 1, SIZE_MAX);
    const Topology whole = count ? mask_topology(mask) : Topology{};
    for (std::uint32_t k = 1; k <= count; ++k) {
        if (!faces_out[k]) continue;
        const Vec3i a = r.lo[k] - Vec3i{1, 1, 1}, b = r.hi[k] + Vec3i{1, 1, 1};
        const auto in_mask = [&](Vec3i q) { return lat.contains(q) && mask(q) != 0; };
        const auto in_cut = [&](Vec3i q) { return lat.contains(q) && mask(q) != 0 && label[lat.index(q)] != k; };
        if (euler_characteristic_26(in_cut, a, b) <= euler_characteristic_26(in_mask, a, b)) continue;
        // The rise is a handle cut only when no piece split off and no cavity opened (a rarer
        // candidate: the whole-mask count, once per region the box test passes).
        Grid<std::uint8_t> cut = mask;
        for (PointIndex i = 0; i < lat.size(); ++i)
            if (label[i] == k) cut[i] = 0;
        const Topology t = mask_topology(cut);
        if (t.components != whole.components || t.cavities != whole.cavities) continue;
        slot[k] = out.size();
        out.push_back({r.size[k], r.centroid(k), Vec3i{0, 0, 0}});
    }
    locate_nearest(lat, label, slot, out);
    return out;
}

}  // namespace liveset
