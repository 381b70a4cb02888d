// numpy <-> Grid conversion with geometry (spacing, origin, direction in LPS, as ITK), and the
// Ctrl-C poll used while the GIL is released.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "bindings.hpp"
#include "image_commands.hpp"

namespace liveset::py {

namespace {

Vec3d vec3(const pyb::object& o, const char* what) {
    const auto a = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(o);
    if (!a || a.size() != 3) throw std::invalid_argument(std::string(what) + " must hold 3 numbers");
    const double* d = a.data();
    return {d[0], d[1], d[2]};
}

template <class T>
pyb::array wrap(Grid<T>&& grid) {
    auto* owned = new Grid<T>(std::move(grid));
    pyb::capsule keep(owned, [](void* p) { delete static_cast<Grid<T>*>(p); });
    const Vec3i d = owned->dims();
    const auto s = static_cast<pyb::ssize_t>(sizeof(T));
    return pyb::array_t<T>({d.x, d.y, d.z}, {s, s * d.x, s * d.x * d.y}, owned->values().data(), keep);
}

template <class T, class Convert>
Grid<T> copy_into(const pyb::array& values, const Lattice& lattice, Convert convert) {
    const auto a = pyb::array_t<double, pyb::array::f_style | pyb::array::forcecast>::ensure(values);
    if (!a) throw std::invalid_argument("expected a numeric 3D array");
    const Vec3i d = lattice.dims();
    if (a.ndim() != 3 || a.shape(0) != d.x || a.shape(1) != d.y || a.shape(2) != d.z)
        throw std::invalid_argument("array shape does not match the geometry's " + lattice.describe());
    Grid<T> g(lattice);
    const double* src = a.data();
    for (std::size_t i = 0; i < g.size(); ++i) g[static_cast<PointIndex>(i)] = convert(src[i]);
    return g;
}

}  // namespace

Lattice lattice_from(const pyb::object& shape, const pyb::object& spacing, const pyb::object& origin,
                     const pyb::object& direction) {
    const Vec3d dims = vec3(shape, "shape");
    const auto dir = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>::ensure(direction);
    if (!dir || dir.size() != 9) throw std::invalid_argument("direction must be a 3x3 matrix");
    Mat3d m{};
    std::memcpy(m.data(), dir.data(), sizeof(double) * 9);
    return Lattice({static_cast<int>(dims.x), static_cast<int>(dims.y), static_cast<int>(dims.z)},
                   vec3(spacing, "spacing"), vec3(origin, "origin"), m);
}

pyb::tuple geometry_of(const Lattice& l) {
    const Vec3d s = l.spacing(), o = l.origin();
    pyb::array_t<double> dir({3, 3});
    std::memcpy(dir.mutable_data(), l.direction().data(), sizeof(double) * 9);
    return pyb::make_tuple(pyb::make_tuple(s.x, s.y, s.z), pyb::make_tuple(o.x, o.y, o.z), dir);
}

Grid<float> grid_from_array(const pyb::array& values, const Lattice& lattice, bool nan_ok) {
    return copy_into<float>(values, lattice, [nan_ok](double v) {
        if (!std::isfinite(v) && !(nan_ok && std::isnan(v)))
            throw std::invalid_argument(nan_ok ? "the image holds infinite values" : "the image holds NaN or infinite values");
        return static_cast<float>(v);
    });
}

cli::Scan scan_from_array(const pyb::array& values, const Lattice& lattice) {
    return cli::scan_of(grid_from_array(values, lattice, true));
}

Grid<std::uint8_t> mask_from_array(const pyb::array& values, const Lattice& lattice) {
    return copy_into<std::uint8_t>(values, lattice, [](double v) {
        if (std::isnan(v)) throw std::invalid_argument("the mask holds NaN values");  // no data is no answer there
        return static_cast<std::uint8_t>(v != 0.0);
    });
}

pyb::array array_from_grid(Grid<float>&& grid) { return wrap(std::move(grid)); }
pyb::array array_from_grid(Grid<std::uint8_t>&& grid) { return wrap(std::move(grid)); }

bool Interrupt::poll() {
    if (flag_.load()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (callback.is_none() && now - last_ < std::chrono::milliseconds(20)) return true;
    last_ = now;
    pyb::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
        error_.emplace();  // fetches the pending exception (KeyboardInterrupt)
        flag_.store(true);
        return false;
    }
    return true;
}

bool Interrupt::poll_with(const std::function<pyb::object()>& make_args) {
    if (callback.is_none()) return poll();
    if (flag_.load()) return false;
    pyb::gil_scoped_acquire gil;
    try {
        callback(make_args());
        if (PyErr_CheckSignals() != 0) throw pyb::error_already_set();
    } catch (pyb::error_already_set& e) {
        error_.emplace(std::move(e));
        flag_.store(true);
        return false;
    }
    return true;
}

void Interrupt::rethrow() {
    error_->restore();
    error_.reset();
    throw pyb::error_already_set();
}

}  // namespace liveset::py
