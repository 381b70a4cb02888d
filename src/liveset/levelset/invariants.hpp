// Consistency checks of a SparseField, used throughout the tests and by long-running soak checks:
// layer lists vs status lattice, value ranges, band continuity, clamped far values, and that the
// outer layers equal what the zero layer implies (the state is the repair's fixed point).
// Plus measures read off φ: enclosed volume and equivalent-sphere radius.
#pragma once

#include <string>
#include <vector>

#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

struct InvariantReport {
    std::vector<std::string> problems;  // empty when every invariant holds (first few listed)
    std::size_t problem_count = 0;
    bool ok() const { return problem_count == 0; }
    std::string summary() const;
};

// Checks, over the whole lattice (O(lattice size)):
//  - every band point is in exactly one layer list, the one its status names, and nothing else is;
//  - L0 values lie in [-0.5, 0.5] and Lk values in [k-0.5, k+0.5];
//  - no hole in the band: a point of layer k≠0 has a neighbour in layer k∓1 (towards zero), every
//    neighbour of a band point is within one layer of it, far points touch only the outermost layer;
//  - far values are exactly ±(N+1) and agree in sign with their status;
//  - outer-layer values equal what the next-inner layer implies (layer_value.hpp).
InvariantReport check_invariants(const SparseField& field);

// Volume enclosed by the zero level set in voxels: Σ clamp(0.5 - φ, 0, 1) over the lattice, which is
// exact to first order for a signed distance.
double enclosed_volume(const SparseField& field);

// Radius of the sphere with the enclosed volume.
double equivalent_radius(const SparseField& field);

}  // namespace liveset
