// Depth-buffer picking: the depth under a pixel of the 3D view, unprojected through the camera
// back to millimetres and lattice index space.
#pragma once

#include <glm/glm.hpp>
#include <optional>

#include "liveset/grid/lattice.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/render/orbit_camera.hpp"

namespace liveset::render {

struct Pick {
    glm::dvec3 world{0.0};  // LPS mm
    glm::dvec3 index{0.0};  // continuous lattice index
    float depth = 1.0f;
};

// The point under window pixel (x, y) with depth `depth` in a viewport of width x height pixels
// (y counted from the TOP row, as mouse coordinates are). nullopt for the background (depth 1).
std::optional<Pick> unproject(double x, double y, float depth, int width, int height, const OrbitCamera& camera,
                              const Lattice& lattice);

// Reads the depth under pixel (x, y) (top-row origin) of `view` - the framebuffer the 3D view was
// just rendered into with `camera` - and unprojects it. nullopt outside the view or on background.
std::optional<Pick> pick(const Framebuffer& view, int x, int y, const OrbitCamera& camera, const Lattice& lattice);

}  // namespace liveset::render
