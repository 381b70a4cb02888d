// Blocks for LargePageAllocator: 2 MiB-aligned, advised for transparent huge pages where the
// kernel offers them (the advice is only a hint; without THP the pages stay small).
#include <sys/mman.h>

#include <cstdlib>
#include <new>

#include "liveset/grid/large_page_allocator.hpp"

namespace liveset::detail {

void* allocate_large(std::size_t bytes) {
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(MADV_HUGEPAGE)
    ::madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return p;
}

void free_large(void* p) noexcept { std::free(p); }

}  // namespace liveset::detail
