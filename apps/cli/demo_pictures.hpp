// The demos' pictures without a display (headless EGL): the surface before and after a repair, seen
// from above.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "liveset/mesh/fragment_mesher.hpp"

namespace liveset::cli {

// The demo's pictures without a display: before.png (the surface of `phi_before`) and after.png
// (the surface in `after`), superior view, rendered headless (EGL) into `dir`. Returns
// {"before": ..., "after": ...}, or null with a one-line warning on stderr when no OpenGL context
// can be had (the demo's other outputs do not depend on it).
nlohmann::json write_before_after_pictures(const std::filesystem::path& dir, const Grid<float>& phi_before,
                                           const FragmentMesher& after);

}  // namespace liveset::cli
