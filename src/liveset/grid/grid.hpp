// Grid<T>: a dense 3D array of T over a Lattice (x fastest), with bounds-checked and clamped access.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/grid/lattice.hpp"

namespace liveset {

namespace detail {

// Grid storage: LargePageAllocator whose elements start default-initialised (a float's value
// unset), so that a whole-lattice grid's first touch, its page faults and the kernel's zeroing of
// fresh pages, is its fill or copy on every thread (for_grid_blocks) instead of one.
template <class T>
struct GridAllocator : LargePageAllocator<T> {
    template <class U>
    struct rebind {
        using other = GridAllocator<U>;
    };
    GridAllocator() = default;
    template <class U>
    explicit GridAllocator(const GridAllocator<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};

// Runs f(context, begin, end) over [0, n) in blocks of `grain`: on the calling thread below two
// blocks, else in parallel (oneTBB, large_pages.cpp). Each element is written by one call.
void for_grid_blocks(std::size_t n, std::size_t grain, void (*f)(void*, std::size_t, std::size_t), void* context);

}  // namespace detail

template <class T>
class Grid {
    // Filled and copied by assignment over default-initialised elements (GridAllocator).
    static_assert(std::is_default_constructible_v<T> && std::is_copy_assignable_v<T>,
                  "a grid's elements are default-constructible and copy-assignable");

public:
    Grid() = default;
    explicit Grid(const Lattice& lattice, T value = T{}) : lattice_(lattice), data_(lattice.size()) { fill(value); }
    Grid(const Grid& other) : lattice_(other.lattice_), data_(other.size()) { copy_from(other); }
    Grid(Grid&&) noexcept = default;
    Grid& operator=(const Grid& other) {
        if (this == &other) return *this;
        if (data_.size() != other.size()) {  // fresh storage (a same-sized grid keeps its own pages)
            Grid copy(other);
            return *this = std::move(copy);
        }
        lattice_ = other.lattice_;
        copy_from(other);
        return *this;
    }
    Grid& operator=(Grid&&) noexcept = default;
    ~Grid() = default;

    const Lattice& lattice() const { return lattice_; }
    Vec3i dims() const { return lattice_.dims(); }
    std::size_t size() const { return data_.size(); }

    T& operator[](PointIndex i) { return data_[i]; }
    const T& operator[](PointIndex i) const { return data_[i]; }
    T& operator()(Vec3i p) { return data_[lattice_.index(p)]; }
    const T& operator()(Vec3i p) const { return data_[lattice_.index(p)]; }

    T& at(Vec3i p) {
        if (!lattice_.contains(p)) throw std::out_of_range("grid index outside the lattice");
        return (*this)(p);
    }
    const T& at(Vec3i p) const {
        if (!lattice_.contains(p)) throw std::out_of_range("grid index outside the lattice");
        return (*this)(p);
    }
    // Value at p with the index clamped onto the lattice (replicate border).
    const T& clamped(Vec3i p) const {
        const Vec3i d = lattice_.dims();
        p.x = std::clamp(p.x, 0, d.x - 1);
        p.y = std::clamp(p.y, 0, d.y - 1);
        p.z = std::clamp(p.z, 0, d.z - 1);
        return (*this)(p);
    }

    std::span<T> values() { return data_; }
    std::span<const T> values() const { return data_; }
    // In parallel 2 MiB blocks for a whole-lattice grid (in_blocks), as the constructor fills.
    void fill(T v) {
        T* const d = data_.data();
        in_blocks([d, &v](std::size_t b, std::size_t e) { std::fill(d + b, d + e, v); });
    }

private:
    // f(begin, end) over the elements, in parallel for a whole-lattice grid (detail::kLargeBlock up).
    template <class F>
    void in_blocks(F f) {
        const std::size_t grain = std::max<std::size_t>(1, detail::kHugePage / sizeof(T));
        if (data_.size() * sizeof(T) < detail::kLargeBlock) {
            f(std::size_t{0}, data_.size());
            return;
        }
        detail::for_grid_blocks(
            data_.size(), grain, [](void* c, std::size_t b, std::size_t e) { (*static_cast<F*>(c))(b, e); }, &f);
    }
    void copy_from(const Grid& other) {
        const T* const from = other.data_.data();
        T* const to = data_.data();
        in_blocks([from, to](std::size_t b, std::size_t e) { std::copy(from + b, from + e, to + b); });
    }

    Lattice lattice_;
    std::vector<T, detail::GridAllocator<T>> data_;
};

}  // namespace liveset
