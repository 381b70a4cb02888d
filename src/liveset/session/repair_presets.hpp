// Named swarm settings shared by `liveset demo`, the viewer and the tests, so the phantom's repair
// is configured in one place.
#pragma once

#include <cstddef>

#include "liveset/swarm/repair.hpp"
#include "liveset/swarm/repair_schedule.hpp"

namespace liveset {

// The settings of the demo's phantom repair (documented in docs/BENCHMARKS.md): 200 agents,
// p = 0.3, growth where the outside is within 2 population sigmas, edit radius 3, only agents
// within 8 voxels of the target edit.
RepairOptions demo_repair_options();

// hole_brush_range (the brush sized to a hole) lives with the repair schedule (swarm/repair_schedule.hpp).

}  // namespace liveset
