// PlaneSplit: a level's sources split at a plane so that two tasks can claim (or push) at once
// and the result is that of one ordered loop, in an order independent of the thread count.
//
// The sources are split at the plane z = mid, the median of their planes: those at least two
// planes below it, those at least two above it, and the seam (mid - 1 .. mid + 1). A source reads
// and writes only its own plane and the two next to it, so the first two sets touch disjoint
// points (planes up to mid - 1, and from mid + 1 on) and run as two tasks, each in source order;
// the seam runs after both. Used where every point a source reaches ends the same whichever source
// reaches it first (a claim's pending code depends on the point's status and the claimer's side; a
// push sweep's value is a min or max): only the order of the claims differs from one ordered loop
// (below, above, seam), and it depends on the sources alone (docs/ARCHITECTURE.md, "Determinism").
#pragma once

#include <tbb/parallel_invoke.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/lattice.hpp"

namespace liveset::detail {

// A level of fewer sources runs as one ordered loop (the split costs two more passes over the
// sources and a task switch; 16 384 is a round choice, not a tuned one).
inline constexpr std::size_t kPlaneSplitMin = 16384;

class PlaneSplit {
public:
    enum Part : int { kBelow = 0, kAbove = 1, kSeam = 2 };

    // Splits `sources` (each a point of a lattice of `planes` z planes); the spans stay valid
    // until the next split.
    void split(std::span<const PointIndex> sources, const IndexDecoder& decoder, int planes);
    std::span<const PointIndex> part(Part p) const { return {points_.data() + static_cast<std::size_t>(p) * size_, used_[p]}; }

    // f(sources of a part, part) for the parts below and above as two tasks, then the seam.
    template <class F>
    void run(const F& f) const {
        tbb::parallel_invoke([&] { f(part(kBelow), kBelow); }, [&] { f(part(kAbove), kAbove); });
        f(part(kSeam), kSeam);
    }

private:
    std::vector<std::uint32_t> z_;      // each source's plane
    std::vector<std::size_t> count_;    // sources per plane
    std::vector<PointIndex> points_;    // the three parts, size_ apart
    std::size_t size_ = 0;
    std::size_t used_[3] = {0, 0, 0};
};

}  // namespace liveset::detail
