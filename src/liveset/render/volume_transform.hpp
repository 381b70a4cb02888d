// The lattice's index -> physical (LPS mm) mapping as GLM matrices, so meshes, agents and picks in
// index space are drawn in millimetres: anisotropic spacing and oblique directions look right.
#pragma once

#include <glm/glm.hpp>

#include "liveset/grid/lattice.hpp"

namespace liveset::render {

// world = M * (i, j, k, 1): M = [D diag(spacing) | origin] (as Lattice::to_world).
glm::dmat4 index_to_world(const Lattice& lattice);
glm::dmat4 world_to_index(const Lattice& lattice);

// Centre and radius (mm) of the sphere around the lattice's corner points.
struct Bounds {
    glm::dvec3 centre{0.0};
    double radius = 1.0;
};
Bounds world_bounds(const Lattice& lattice);

inline glm::dvec3 to_glm(Vec3d v) { return {v.x, v.y, v.z}; }
inline Vec3d from_glm(glm::dvec3 v) { return {v.x, v.y, v.z}; }

}  // namespace liveset::render
