// Named swarm settings.
#include "liveset/session/repair_presets.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace liveset {

RepairOptions demo_repair_options() {
    RepairOptions ro;
    ro.swarm.agents = 200;
    ro.swarm.act_probability = 0.3;
    ro.swarm.expand_sigmas = 2.0;  // grow where the outside is within 2 population sigmas
    ro.swarm.edit_radius = 3.0;
    ro.swarm.edit_range = 8.0;     // only agents within 8 voxels of the target edit
    return ro;
}

double hole_brush_range(std::size_t hole_voxels, double shell_thickness, double max_range) {
    if (!(std::isfinite(shell_thickness) && shell_thickness > 0))
        throw std::invalid_argument("hole brush: the shell thickness must be finite and > 0 voxels");
    if (!(std::isfinite(max_range) && max_range >= 3.0))
        throw std::invalid_argument("hole brush: the largest range must be finite and >= 3 voxels");
    const double radius = std::sqrt(static_cast<double>(hole_voxels) / (std::numbers::pi * shell_thickness));
    return std::clamp(radius + 1.0, 3.0, max_range);
}

}  // namespace liveset
