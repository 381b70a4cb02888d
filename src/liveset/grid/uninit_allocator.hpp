// UninitAllocator<T>: std::allocator whose value-initialisation (resize, a sized constructor)
// leaves a new element of a trivial type unset, for working buffers sized first and then written
// once per entry: std::vector<PointIndex>::resize zero-fills, a memset of the whole growth.
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace liveset {

template <class T>
struct UninitAllocator : std::allocator<T> {
    static_assert(std::is_trivially_default_constructible_v<T>, "for trivial element types only");
    using value_type = T;

    UninitAllocator() = default;
    template <class U>
    explicit UninitAllocator(const UninitAllocator<U>&) noexcept {}

    // No arguments: default-initialised (left unset). With arguments std::allocator_traits finds no
    // construct here and constructs as usual (std::construct_at).
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U>
    bool operator==(const UninitAllocator<U>&) const noexcept {
        return true;
    }
};

template <class T>
using UninitVector = std::vector<T, UninitAllocator<T>>;

}  // namespace liveset
