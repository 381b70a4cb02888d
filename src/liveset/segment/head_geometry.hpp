// Head geometry for the automatic brain mask (brain_mask.cpp): which way is up, the head's top,
// width and cranial part, and how much of a mask's boundary lies at the head's surface or at a cut.
// Internal to the segment library.
#pragma once

#include <cstddef>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/brain_histogram.hpp"

namespace liveset::brain_detail {

// The brain boundary's share that lies within `near_mm` of the head surface (boundary: mask voxels
// with a 6-neighbour outside the mask inside the lattice).
double surface_contact(const Mask& mask, const Grid<float>& head_depth, double near_mm);

// Which way is up in the image: height (mm) = g · voxel index, and the head's cross-section in the
// array's face that looks most inferior (mm²), where a neck leaves the field of view.
struct Vertical {
    double g[3] = {0, 0, 0};
    double exit_mm2 = 0;
    double height(Vec3i p) const { return g[0] * p.x + g[1] * p.y + g[2] * p.z; }
};

// The head's highest point along `up`.
double head_top(const Mask& head, const Vertical& up);

// From the header: the world's superior axis (LPS z; the direction cosines included), the inferior
// face the one whose axis runs most along it. From the head (a header without orientation): the face
// the head leaves the field of view through most is inferior, up runs away from it.
Vertical vertical(const Mask& head, bool from_header);

// The head within `extent_mm` of its highest voxel along `up`; `below` counts what is left out.
// 0: the whole head.
Mask cranial(const Mask& head, const Vertical& up, double extent_mm, std::size_t& below);

// The head's widest cross-section across `up` within `depth_mm` of its top, as the diameter of the
// disc of that area (mm): the volume of each layer of height, one slice thick.
double head_diameter_mm(const Mask& head, const Vertical& up, double depth_mm);

// The brain's cross-section where the head is cut at height `cut` (mm²): its voxels within a slab
// above the cut, per mm of height. The slab is whole slices of the array's most vertical axis, at
// least 3 mm (a 6 mm slice: one), so that quantised heights count no slice twice.
double cut_contact_mm2(const Mask& brain, const Vertical& up, double cut);

}  // namespace liveset::brain_detail
