// Stable LSD radix sort of a vector by a 32-bit key: the order std::stable_sort by that key gives,
// in one counting pass per key byte that any element uses.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace liveset {

// Sorts v by key(element) (a std::uint32_t), keeping the input order of equal keys; `scratch` is
// working space (its contents are lost; pass the same vector again to reuse its memory).
template <class T, class Alloc, class Key>
void stable_radix_sort(std::vector<T, Alloc>& v, Key key, std::vector<T, Alloc>& scratch) {
    std::uint32_t top = 0;
    for (const T& e : v) top |= key(e);
    scratch.resize(v.size());
    for (int shift = 0; shift < 32 && (top >> shift) != 0; shift += 8) {
        std::array<std::size_t, 257> start{};
        for (const T& e : v) ++start[((key(e) >> shift) & 255u) + 1];
        for (std::size_t b = 0; b < 256; ++b) start[b + 1] += start[b];
        for (const T& e : v) scratch[start[(key(e) >> shift) & 255u]++] = e;
        v.swap(scratch);
    }
}

}  // namespace liveset
