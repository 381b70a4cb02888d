// Blocks for LargePageAllocator: 2 MiB-aligned, advised for transparent huge pages where the
// kernel offers them (the advice is only a hint; without THP the pages stay small), and a few
// freed blocks kept for the next request of their size (see large_page_allocator.hpp); a grid's
// fill and copy over them on every thread (grid.hpp).
#include <sys/mman.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstdlib>
#include <mutex>
#include <new>
#include <utility>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/grid/large_page_allocator.hpp"

namespace liveset::detail {

namespace {

std::size_t rounded(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

#if defined(__SANITIZE_ADDRESS__)
#define LIVESET_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LIVESET_ASAN 1
#endif
#endif
#if defined(LIVESET_ASAN)
constexpr bool kRecycle = false;  // AddressSanitizer sees every block's use after its free
#else
constexpr bool kRecycle = true;
#endif

// Freed blocks, oldest first, within kRecycledBytes and kRecycledBlocks. Never destroyed: a grid
// with static storage may be freed after every other static object.
struct Recycled {
    std::mutex mutex;
    std::vector<std::pair<void*, std::size_t>> blocks;
    std::size_t bytes = 0;
};

Recycled& recycled_blocks() {
    static Recycled* const r = new Recycled;
    return *r;
}

}  // namespace

void* allocate_large(std::size_t bytes) {
    const std::size_t size = rounded(bytes);
    if (kRecycle) {
        Recycled& r = recycled_blocks();
        const std::lock_guard lock(r.mutex);
        for (std::size_t k = r.blocks.size(); k-- > 0;)  // the most recently freed first (warmest)
            if (r.blocks[k].second == size) {
                void* const p = r.blocks[k].first;
                r.blocks.erase(r.blocks.begin() + static_cast<std::ptrdiff_t>(k));
                r.bytes -= size;
                return p;
            }
    }
    void* p = std::aligned_alloc(kHugePage, size);
    if (p == nullptr && kRecycle) {  // the kept blocks given back first
        release_recycled();
        p = std::aligned_alloc(kHugePage, size);
    }
    if (p == nullptr) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
    ::madvise(p, size, MADV_HUGEPAGE);
#endif
    return p;
}

void free_large(void* p, std::size_t bytes) noexcept {
    const std::size_t size = rounded(bytes);
    if (!kRecycle || size > kRecycledBytes) {
        std::free(p);
        return;
    }
    std::vector<void*> evicted;
    {
        Recycled& r = recycled_blocks();
        const std::lock_guard lock(r.mutex);
        std::size_t drop = 0;  // the oldest blocks that make room
        std::size_t bytes_after = r.bytes + size;
        while (drop < r.blocks.size() && (bytes_after > kRecycledBytes || r.blocks.size() - drop + 1 > kRecycledBlocks)) {
            bytes_after -= r.blocks[drop].second;
            ++drop;
        }
        try {
            evicted.reserve(drop);
            r.blocks.reserve(r.blocks.size() - drop + 1);
        } catch (const std::bad_alloc&) {
            std::free(p);  // no room to keep it: freed as before
            return;
        }
        for (std::size_t k = 0; k < drop; ++k) evicted.push_back(r.blocks[k].first);
        r.blocks.erase(r.blocks.begin(), r.blocks.begin() + static_cast<std::ptrdiff_t>(drop));
        r.blocks.emplace_back(p, size);
        r.bytes = bytes_after;
    }
    for (void* e : evicted) std::free(e);
}

void for_grid_blocks(std::size_t n, std::size_t grain, void (*f)(void*, std::size_t, std::size_t), void* context) {
    if (n < 2 * grain) {
        f(context, 0, n);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                      [&](const tbb::blocked_range<std::size_t>& r) { f(context, r.begin(), r.end()); });
}

bool recycles_blocks() noexcept { return kRecycle; }

void release_recycled() noexcept {
    std::vector<std::pair<void*, std::size_t>> kept;
    {
        Recycled& r = recycled_blocks();
        const std::lock_guard lock(r.mutex);
        kept.swap(r.blocks);
        r.bytes = 0;
    }
    for (const auto& block : kept) std::free(block.first);
}

std::pair<std::size_t, std::size_t> recycled() noexcept {
    Recycled& r = recycled_blocks();
    const std::lock_guard lock(r.mutex);
    return {r.blocks.size(), r.bytes};
}

}  // namespace liveset::detail
