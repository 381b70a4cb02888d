// PlaneSplit: the split of a level's sources at their median plane (see plane_split.hpp).
#include "liveset/levelset/plane_split.hpp"

namespace liveset::detail {

void PlaneSplit::split(std::span<const PointIndex> sources, const IndexDecoder& index_decoder, int planes) {
    const IndexDecoder decoder = index_decoder;  // a local: a store to z_of could alias the caller's
    const std::size_t n = sources.size();
    size_ = n;
    z_.resize(n);
    count_.assign(static_cast<std::size_t>(planes), 0);
    // Through local pointers: the members would be reloaded after every store.
    std::uint32_t* const z_of = z_.data();
    std::size_t* const count = count_.data();
    for (std::size_t m = 0; m < n; ++m) {
        const std::uint32_t z = decoder.z(sources[m]);
        z_of[m] = z;
        ++count[z];
    }
    std::uint32_t mid = 0;
    for (std::size_t seen = 0; mid + 1 < static_cast<std::uint32_t>(planes); ++mid) {
        seen += count[mid];
        if (2 * seen >= n) break;
    }
    // Three outputs, each written at every source and advanced only for its own: no branch on
    // the plane (the sources are only roughly in lattice order).
    points_.resize(3 * n);
    PointIndex* const out[3] = {points_.data(), points_.data() + n, points_.data() + 2 * n};
    std::size_t used[3] = {0, 0, 0};
    for (std::size_t m = 0; m < n; ++m) {
        const std::uint32_t z = z_of[m];
        const std::size_t below = z + 2 <= mid ? 1 : 0, above = z >= mid + 2 ? 1 : 0;
        out[kBelow][used[kBelow]] = sources[m];
        out[kAbove][used[kAbove]] = sources[m];
        out[kSeam][used[kSeam]] = sources[m];
        used[kBelow] += below;
        used[kAbove] += above;
        used[kSeam] += 1 - below - above;
    }
    for (int p = 0; p < 3; ++p) used_[p] = used[p];
}

}  // namespace liveset::detail
