// Whole-image loops of the preprocessing on every thread (oneTBB): maps that write each element
// from its own index only, and reductions over fixed parts folded in order - integer counts and
// histograms, minima and maxima - whose results are the serial loop's bit for bit whatever the
// thread count or the scheduling.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace liveset::voxel_loops {

inline constexpr std::size_t kBlock = std::size_t{1} << 16;  // voxels per task of a whole-image loop
inline constexpr std::size_t kMaxParts = 64;                 // parts of a reduction

// f(i) for every i in [0, n).
template <class F>
void for_each(std::size_t n, const F& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kBlock), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
}

// [0, n) in min(kMaxParts, n / grain) parts (at least one) of consecutive items, set by n and
// grain alone: part p = body(begin, end, zero) for each, in parallel, then fold(fold(part 0,
// part 1), part 2)... in part order. The fold runs whenever there are two parts, on any thread
// count (so a test of a wrong fold fails on one thread too).
template <class T, class Body, class Fold>
T reduce(std::size_t n, std::size_t grain, const T& zero, const Body& body, const Fold& fold) {
    const std::size_t parts = std::clamp<std::size_t>(n / std::max<std::size_t>(grain, 1), 1, kMaxParts);
    std::vector<T> part(parts, zero);
    tbb::parallel_for(std::size_t{0}, parts, [&](std::size_t p) { part[p] = body(n * p / parts, n * (p + 1) / parts, std::move(part[p])); });
    T out = std::move(part.front());
    for (std::size_t p = 1; p < parts; ++p) out = fold(std::move(out), part[p]);
    return out;
}

// An ordered compaction over reduce's parts of [0, n): count(begin, end) what each part writes, in
// parallel; size(total) once; then write(begin, end, at) in parallel, each part from `at` = first
// plus the counts of the parts before it. The outputs land in item order, the same on any thread
// count; each part must write only its own items' entries (and its own slots from `at`).
template <class Count, class Size, class Write>
void counted_writes(std::size_t n, std::size_t grain, std::size_t first, const Count& count, const Size& size, const Write& write) {
    const std::size_t parts = std::clamp<std::size_t>(n / std::max<std::size_t>(grain, 1), 1, kMaxParts);
    const auto begin = [&](std::size_t p) { return n * p / parts; };
    std::vector<std::size_t> at(parts + 1, 0);
    at[0] = first;
    tbb::parallel_for(std::size_t{0}, parts, [&](std::size_t p) { at[p + 1] = count(begin(p), begin(p + 1)); });
    for (std::size_t p = 0; p < parts; ++p) at[p + 1] += at[p];
    size(at[parts]);
    tbb::parallel_for(std::size_t{0}, parts, [&](std::size_t p) { write(begin(p), begin(p + 1), at[p]); });
}

// How many i in [0, n) satisfy pred(i).
template <class P>
std::size_t count_if(std::size_t n, const P& pred) {
    return reduce(
        n, kBlock, std::size_t{0},
        [&](std::size_t b, std::size_t e, std::size_t c) {
            for (std::size_t i = b; i != e; ++i) c += pred(i) ? 1 : 0;
            return c;
        },
        [](std::size_t a, std::size_t b) { return a + b; });
}

// a + b bin by bin (the fold of per-part counts; b no longer than a).
inline std::vector<std::size_t> add_counts(std::vector<std::size_t> a, const std::vector<std::size_t>& b) {
    for (std::size_t k = 0; k < b.size(); ++k) a[k] += b[k];
    return a;
}

// Counts per bin over [0, n): bin(i) gives i's bin, or a value ≥ bins for none. Integer counts,
// so a caller's histogram of doubles built from them (each count exact below 2^53) holds the
// serial loop's `+= 1.0` sums.
template <class B>
std::vector<std::size_t> histogram(std::size_t n, std::size_t bins, const B& bin) {
    using Counts = std::vector<std::size_t>;
    return reduce(
        n, kBlock, Counts(bins, 0),
        [&](std::size_t b, std::size_t e, Counts c) {
            for (std::size_t i = b; i != e; ++i) {
                const std::size_t k = bin(i);
                if (k < bins) ++c[k];
            }
            return c;
        },
        add_counts);
}

}  // namespace liveset::voxel_loops
