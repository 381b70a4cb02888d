// LargePageAllocator<T>: std::allocator for small arrays; an array of 4 MiB or more is placed on
// 2 MiB boundaries and offered to the kernel for transparent huge pages (Linux, madvise mode), so
// that first touching a whole-lattice grid takes one page fault per 2 MiB instead of per 4 KiB
// (BrainWeb set-up: 1.3 s -> 0.7-1.0 s on a 2-core VM, docs/BENCHMARKS.md). A freed block is kept
// (up to kRecycledBlocks blocks and kRecycledBytes, the oldest let go first) for the next request
// of its size: the automatic brain mask and N4 make and drop dozens of whole-lattice grids, each
// of whose fresh pages the kernel would zero before the grid's own fill (16 % of a BrainWeb
// preprocessing's samples, half of it saved; docs/BENCHMARKS.md, session 74). Not under
// AddressSanitizer; every kept block is given back when an allocation fails, or by
// detail::release_recycled() when a stage whose sizes no later one asks for ends.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace liveset {

namespace detail {
inline constexpr std::size_t kHugePage = std::size_t{2} << 20;   // the blocks' alignment and granule
inline constexpr std::size_t kLargeBlock = std::size_t{4} << 20;  // from here on: huge-page blocks
inline constexpr std::size_t kRecycledBytes = std::size_t{256} << 20;
inline constexpr std::size_t kRecycledBlocks = 12;
void* allocate_large(std::size_t bytes);  // throws std::bad_alloc
void free_large(void* p, std::size_t bytes) noexcept;  // bytes: as allocated
bool recycles_blocks() noexcept;                        // false under AddressSanitizer
std::pair<std::size_t, std::size_t> recycled() noexcept;  // blocks kept and their bytes
void release_recycled() noexcept;                       // every kept block given back (a stage whose sizes no later one asks for ends)
}  // namespace detail

template <class T>
struct LargePageAllocator {
    using value_type = T;

    LargePageAllocator() = default;
    template <class U>
    explicit LargePageAllocator(const LargePageAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
        if (!large(n)) return std::allocator<T>{}.allocate(n);
        return static_cast<T*>(detail::allocate_large(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (large(n)) detail::free_large(p, n * sizeof(T));
        else std::allocator<T>{}.deallocate(p, n);
    }
    template <class U>
    bool operator==(const LargePageAllocator<U>&) const noexcept { return true; }

private:
    static bool large(std::size_t n) { return n * sizeof(T) >= detail::kLargeBlock; }
};

// A vector on these blocks: a grid's storage, and large temporaries (a copy of a brain's voxels,
// a read buffer) whose 4 KiB page faults would cost more than their use on a VM.
template <class T>
using LargeVector = std::vector<T, LargePageAllocator<T>>;

}  // namespace liveset
