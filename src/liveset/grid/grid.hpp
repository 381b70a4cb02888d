// Grid<T>: a dense 3D array of T over a Lattice (x fastest), with bounds-checked and clamped access.
#pragma once

#include <algorithm>
#include <span>
#include <stdexcept>
#include <vector>

#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/grid/lattice.hpp"

namespace liveset {

template <class T>
class Grid {
public:
    Grid() = default;
    explicit Grid(const Lattice& lattice, T fill = T{}) : lattice_(lattice), data_(lattice.size(), fill) {}

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
    void fill(T v) { std::fill(data_.begin(), data_.end(), v); }

private:
    Lattice lattice_;
    LargeVector<T> data_;
};

}  // namespace liveset
