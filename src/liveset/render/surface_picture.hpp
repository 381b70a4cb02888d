// One-off pictures of a surface without a window: the demos' before/after views, rendered with
// an EGL surfaceless context into an offscreen framebuffer and written as a PNG.
#pragma once

#include <string>

#include "liveset/mesh/fragment_mesher.hpp"

namespace liveset::render {

// Renders the surface in `mesher` seen from a named view (orbit_camera.hpp: "superior", ...),
// framed on the surface, `supersample`× supersampled, into the PNG `path`. Creates its own headless
// context. Throws std::invalid_argument on an unknown view, std::runtime_error when no OpenGL
// context can be had or the file cannot be written.
void render_surface_png(const FragmentMesher& mesher, const std::string& path, const std::string& view, int width,
                        int height, int supersample);

}  // namespace liveset::render
