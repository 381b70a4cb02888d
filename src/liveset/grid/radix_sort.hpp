// Stable LSD radix sort of a vector by a 32-bit key: the order std::stable_sort by that key gives,
// in one counting pass per key byte that any element uses (in parallel chunks for long vectors).
#pragma once

#include <tbb/parallel_for.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace liveset {

// Sorts v by key(element) (a std::uint32_t), keeping the input order of equal keys; `scratch` is
// working space (its contents are lost; pass the same vector again to reuse its memory).
// From 65 536 elements each pass counts and scatters eight fixed chunks as parallel tasks, chunk c
// writing each bucket's elements after those of chunks before it: the same stable order, so the
// same result on any thread count.
template <class T, class Alloc, class Key>
void stable_radix_sort(std::vector<T, Alloc>& v, Key key, std::vector<T, Alloc>& scratch) {
    constexpr std::size_t kParallelMin = 65536, kChunks = 8;
    const std::size_t n = v.size();
    const std::size_t chunks = n < kParallelMin ? 1 : kChunks;
    const auto chunk_begin = [&](std::size_t c) { return n * c / chunks; };
    std::array<std::uint32_t, kChunks> chunk_top{};
    const auto for_chunks = [&](const auto& f) {
        if (chunks == 1) {
            f(0);
        } else {
            tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) { f(c); });
        }
    };
    for_chunks([&](std::size_t c) {
        std::uint32_t top = 0;
        const std::size_t e = chunk_begin(c + 1);
        for (std::size_t m = chunk_begin(c); m < e; ++m) top |= key(v[m]);
        chunk_top[c] = top;
    });
    std::uint32_t top = 0;
    for (const std::uint32_t t : chunk_top) top |= t;
    scratch.resize(n);
    std::array<std::array<std::size_t, 256>, kChunks> start;
    for (int shift = 0; shift < 32 && (top >> shift) != 0; shift += 8) {
        for_chunks([&](std::size_t c) {
            std::array<std::size_t, 256>& count = start[c];
            count.fill(0);
            const std::size_t e = chunk_begin(c + 1);
            for (std::size_t m = chunk_begin(c); m < e; ++m) ++count[(key(v[m]) >> shift) & 255u];
        });
        std::size_t at = 0;  // bucket by bucket, chunk by chunk: each chunk's first slot per bucket
        for (std::size_t b = 0; b < 256; ++b)
            for (std::size_t c = 0; c < chunks; ++c) {
                const std::size_t count = start[c][b];
                start[c][b] = at;
                at += count;
            }
        for_chunks([&](std::size_t c) {
            std::array<std::size_t, 256>& next = start[c];
            const std::size_t e = chunk_begin(c + 1);
            for (std::size_t m = chunk_begin(c); m < e; ++m) scratch[next[(key(v[m]) >> shift) & 255u]++] = v[m];
        });
        v.swap(scratch);
    }
}

}  // namespace liveset
