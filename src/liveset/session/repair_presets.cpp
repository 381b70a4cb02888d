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

}  // namespace liveset
