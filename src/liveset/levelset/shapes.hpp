// Analytic signed distances (index space, voxels, negative inside) used to initialise level sets:
// spheres, axis-aligned boxes, tori, and unions of seed spheres. Constructors validate parameters
// and throw std::invalid_argument with a useful message.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "liveset/grid/lattice.hpp"

namespace liveset::shapes {

struct Sphere {
    Vec3d center;
    double radius;
    Sphere(Vec3d c, double r) : center(c), radius(r) {
        if (!all_finite(c)) throw std::invalid_argument("sphere centre must be finite");
        if (!std::isfinite(r) || r <= 0) throw std::invalid_argument("sphere radius must be positive");
    }
    double operator()(Vec3d p) const { return norm(p - center) - radius; }
};

struct Box {
    Vec3d center;
    Vec3d half;  // half extents
    Box(Vec3d c, Vec3d h) : center(c), half(h) {
        if (!all_finite(c) || !all_finite(h)) throw std::invalid_argument("box centre and size must be finite");
        if (h.x <= 0 || h.y <= 0 || h.z <= 0) throw std::invalid_argument("box size must be positive");
    }
    double operator()(Vec3d p) const {
        const Vec3d q{std::abs(p.x - center.x) - half.x, std::abs(p.y - center.y) - half.y,
                      std::abs(p.z - center.z) - half.z};
        const Vec3d outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
        return norm(outside) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
};

// Torus around the z axis through `center`: ring radius R, tube radius r.
struct Torus {
    Vec3d center;
    double ring, tube;
    Torus(Vec3d c, double R, double r) : center(c), ring(R), tube(r) {
        if (!all_finite(c) || !std::isfinite(R) || !std::isfinite(r) || r <= 0 || R <= r)
            throw std::invalid_argument("torus needs 0 < tube radius < ring radius");
    }
    double operator()(Vec3d p) const {
        const Vec3d d = p - center;
        const double qx = std::sqrt(d.x * d.x + d.y * d.y) - ring;
        return std::sqrt(qx * qx + d.z * d.z) - tube;
    }
};

// Union of seed spheres; every centre must lie inside the lattice.
struct SeedSpheres {
    std::vector<Sphere> seeds;
    SeedSpheres(const Lattice& lattice, std::vector<Sphere> s) : seeds(std::move(s)) {
        if (seeds.empty()) throw std::invalid_argument("at least one seed is needed");
        for (const Sphere& sp : seeds)
            if (!lattice.contains(sp.center))
                throw std::invalid_argument("seed centre (" + std::to_string(sp.center.x) + "," +
                                            std::to_string(sp.center.y) + "," + std::to_string(sp.center.z) +
                                            ") lies outside the " + lattice.describe() + " lattice");
    }
    double operator()(Vec3d p) const {
        double d = std::numeric_limits<double>::infinity();
        for (const Sphere& s : seeds) d = std::min(d, s(p));
        return d;
    }
};

}  // namespace liveset::shapes
