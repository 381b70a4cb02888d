// Named swarm settings shared by `liveset demo`, the viewer and the tests, so the phantom's repair
// is configured in one place.
#pragma once

#include <cstddef>

#include "liveset/swarm/repair.hpp"

namespace liveset {

// The settings of the demo's phantom repair (documented in docs/BENCHMARKS.md): 200 agents,
// p = 0.3, growth where the outside is within 2 population sigmas, edit radius 3, only agents
// within 8 voxels of the target edit.
RepairOptions demo_repair_options();

// The brush a user sizes to a hole before clicking at its centre (ITK-SNAP users size the paint
// brush the same way): the radius of a disc of `hole_voxels` voxels through a shell
// `shell_thickness` voxels thick, plus one voxel so the brush reaches the hole's rim, clamped to
// [3, max_range] voxels. The demo and the phantom tests set SwarmOptions::edit_range to it for
// each hole they target: a fixed 8-voxel brush keeps editing the shell around a hole that has
// shrunk to a few voxels and grows it into white matter and CSF (docs/BENCHMARKS.md).
// Throws std::invalid_argument for a non-positive thickness or max_range < 3.
double hole_brush_range(std::size_t hole_voxels, double shell_thickness = 3.0, double max_range = 8.0);

}  // namespace liveset
