// Shared pieces of the pybind11 module: numpy <-> Grid conversion with geometry, the interrupt
// check run while the GIL is released, and the registration functions of each binding file.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/brain_mask.hpp"

namespace liveset::cli {
struct Scan;  // image_commands.hpp
}

namespace liveset::py {

namespace pyb = pybind11;

// The geometry as Python sees it: spacing (3), origin (3, LPS mm), direction (3x3, columns are
// the axes in LPS world space), exactly ITK's convention.
Lattice lattice_from(const pyb::object& shape, const pyb::object& spacing, const pyb::object& origin,
                     const pyb::object& direction);
pyb::tuple geometry_of(const Lattice& lattice);  // (spacing, origin, direction) as tuples / 3x3 array

// A 3D numpy array (any dtype, any order; index [i, j, k]) copied into a Grid on `lattice`.
// Throws std::invalid_argument when the shape differs from the lattice's dims or holds NaN/inf
// (NaN kept with `nan_ok`: an image to write as it is).
Grid<float> grid_from_array(const pyb::array& values, const Lattice& lattice, bool nan_ok = false);
// A scan handed as an array (segment, sessions, holes): NaN voxels — a masked image's "no data",
// as liveset.read keeps them — lowered below the rest, as the CLI reads a file (cli::read_scan).
cli::Scan scan_from_array(const pyb::array& values, const Lattice& lattice);
Grid<std::uint8_t> mask_from_array(const pyb::array& values, const Lattice& lattice);  // non-zero -> 1; NaN refused
// Zero-copy: the Grid moves into a capsule that the Fortran-ordered array (shape I, J, K) keeps alive.
pyb::array array_from_grid(Grid<float>&& grid);
pyb::array array_from_grid(Grid<std::uint8_t>&& grid);
// How the automatic brain mask is looked for in an image whose file did (not) give an orientation
// (Image.oriented), as the CLI's cli::brain_mask_options(header).
BrainMaskOptions brain_options_for(bool oriented);

// Ctrl-C while the GIL is released: poll() (called from a long C++ loop, on the thread that
// released the GIL) re-acquires the GIL at most every 20 ms, runs Python's signal handlers and,
// when one raised (KeyboardInterrupt), sets flag() and keeps the error for rethrow().
class Interrupt {
public:
    bool poll();                       // false: stop
    const std::atomic<bool>& flag() const { return flag_; }
    bool raised() const { return error_.has_value(); }
    [[noreturn]] void rethrow();       // with the GIL held
    // Also calls `callback(args)` (with the GIL) each poll when set; its exception stops the run too.
    pyb::object callback = pyb::none();
    bool poll_with(const std::function<pyb::object()>& make_args);

private:
    std::atomic<bool> flag_{false};
    std::optional<pyb::error_already_set> error_;
    std::chrono::steady_clock::time_point last_{};
};

void register_core(pyb::module_& m);
void register_session(pyb::module_& m);

}  // namespace liveset::py
