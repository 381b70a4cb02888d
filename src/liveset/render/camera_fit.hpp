// Framing the 3D view to the surface: the world-space box of the mesher's vertices, and the zoom
// at which every corner of a box lies inside the view (a margin from its edges) for a camera's
// direction and a viewport's aspect ratio.
#pragma once

#include <glm/glm.hpp>

#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/render/orbit_camera.hpp"

namespace liveset::render {

struct Box {
    glm::dvec3 lo{0.0}, hi{0.0};
};

// The box around the surface's vertices (world mm); the lattice's box when there is no surface.
Box surface_box(const FragmentMesher& mesher);

// The zoom (CameraPose::zoom, clamped to OrbitCamera's range) at which `camera`, with its
// current yaw, pitch and pan, shows all of `box` with each corner at most `fill` of the way from
// the view's centre to its edge (vertically and horizontally, viewport width / height = aspect).
double zoom_to_fit(const OrbitCamera& camera, const Box& box, double aspect, double fill = 0.9);

}  // namespace liveset::render
