// Perforations of a segmented shell: missed-truth regions joining the inner tissue to the outside.
#include "liveset/eval/perforations.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "liveset/eval/topology.hpp"

namespace liveset {

std::vector<Perforation> find_perforations(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth,
                                           const Grid<std::uint8_t>& inner) {
    if (!(mask.dims() == truth.dims()) || !(mask.dims() == inner.dims()))
        throw std::invalid_argument("find_perforations: mask, truth and inner differ in size");
    const Lattice& lat = mask.lattice();
    Grid<std::uint8_t> missed(lat, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) missed[i] = truth[i] && !mask[i];
    std::size_t count = 0;
    const std::vector<std::uint32_t> label = label_components(missed, 6, &count);
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
    std::stable_sort(out.begin(), out.end(), [](const Perforation& a, const Perforation& b) { return a.voxels > b.voxels; });
    return out;
}

}  // namespace liveset
