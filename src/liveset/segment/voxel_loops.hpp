// Whole-image loops of the preprocessing on every thread (oneTBB), in blocks of 64 Ki elements:
// maps that write each element from its own index only, integer counts and histograms, minima and
// maxima - results that are the serial loop's bit for bit whatever the thread count or the order.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

namespace liveset::voxel_loops {

inline constexpr std::size_t kBlock = std::size_t{1} << 16;

// f(i) for every i in [0, n).
template <class F>
void for_each(std::size_t n, const F& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBlock), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
}

// How many i in [0, n) satisfy pred(i).
template <class P>
std::size_t count_if(std::size_t n, const P& pred) {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, kBlock), std::size_t{0},
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t c) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) c += pred(i) ? 1 : 0;
            return c;
        },
        std::plus<>());
}

// Counts per bin over [0, n): bin(i) gives i's bin, or a value ≥ bins for none. Integer counts,
// so a caller's histogram of doubles built from them (each count exact below 2^53) holds the
// serial loop's `+= 1.0` sums.
template <class B>
std::vector<std::size_t> histogram(std::size_t n, std::size_t bins, const B& bin) {
    using Counts = std::vector<std::size_t>;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, kBlock), Counts(bins, 0),
        [&](const tbb::blocked_range<std::size_t>& r, Counts c) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::size_t k = bin(i);
                if (k < bins) ++c[k];
            }
            return c;
        },
        [](Counts a, const Counts& b) {
            for (std::size_t k = 0; k < a.size(); ++k) a[k] += b[k];
            return a;
        });
}

}  // namespace liveset::voxel_loops
