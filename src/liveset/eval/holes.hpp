// Holes of a segmented sheet found without ground truth: where the tissue the sheet encloses (e.g.
// white matter under the cortical grey matter) meets the outside (CSF, background) through
// unsegmented voxels that look like the sheet's own tissue — a gap in the sheet. The truth-free
// twin of find_perforations (perforations.hpp): the truth is replaced by the image's intensity
// classes (the sheet's band [sheet_lower, sheet_upper) between the outer and the inner tissue).
//
// Rule. Every voxel outside the mask is `inner` (intensity ≥ sheet_upper), `gap` (in the band) or
// `outer` (below sheet_lower, or outside the ROI / the image). The outside that counts is the outer
// voxels 6-connected through outer voxels to the ROI's exterior or the image border: CSF enclosed
// by the inner tissue (the ventricles under white matter) is no outside of the cortex. A candidate
// hole is a 6-connected component of gap voxels that touches both an inner voxel and a counted
// outer voxel through its faces, and of which at least min_sheet_share of the voxels touch the mask. Ranked by size, largest first; its site (a voxel of the gap) is the
// one nearest the centroid of the component's voxels that touch the inner or the outer tissue.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct HoleFinderOptions {
    double sheet_lower = 0.0;  // raw intensity: below it the outer tissue (CSF)
    double sheet_upper = 0.0;  // raw intensity: at or above it the inner tissue (WM)
    std::size_t min_voxels = 1;  // smaller candidates are left out
    // A gap in the sheet is bordered by the sheet: candidates with fewer than this share of their
    // voxels touching the mask (face neighbours) are left out (a gap between white-matter-like
    // and dark tissue where no sheet was segmented at all, e.g. muscle under the brain).
    double min_sheet_share = 0.1;
    void validate() const;       // std::invalid_argument with a one-line message
};

struct HoleCandidate {
    std::size_t voxels = 0;     // gap voxels in the component
    std::size_t rim = 0;        // its voxels that touch the inner or the outer tissue
    std::size_t sheet = 0;      // its voxels that touch the mask
    Vec3d centroid;             // index space, of the whole component
    Vec3i site;                 // a voxel of the component: aim --target here
};

// `mask` the segmented sheet (non-zero inside), `image` raw intensities, `roi` optional (non-zero
// inside). Same dimensions required (std::invalid_argument). Deterministic, O(volume).
std::vector<HoleCandidate> find_holes(const Grid<std::uint8_t>& mask, const Grid<float>& image,
                                      const Grid<std::uint8_t>* roi, const HoleFinderOptions& options);

// The voxels of every candidate hole (non-zero), for overlap with the truth's perforations.
Grid<std::uint8_t> hole_voxels(const Grid<std::uint8_t>& mask, const Grid<float>& image,
                               const Grid<std::uint8_t>* roi, const HoleFinderOptions& options);

// The finder's verdict at one place, as a repair reports it before and after: the number of
// candidate-hole voxels (non-zero in `holes`, from hole_voxels) within `radius` voxels of `site`.
std::size_t hole_voxels_near(const Grid<std::uint8_t>& holes, Vec3d site, double radius);

// Genus (tunnels/handles, topology.hpp) of the mask inside the box of half-width r around c: the
// local topology at a repair target.
long local_genus(const Grid<std::uint8_t>& mask, Vec3i c, int r);

// The finder's verdict on one repair target: hole voxels (from hole_voxels) within `radius` of it
// before and after, closed when they at least halved; the local genus (box of half-width 8) too.
struct HoleVerdict {
    std::size_t before = 0, after = 0;
    long genus_before = 0, genus_after = 0;
    bool closed = false;
};
HoleVerdict hole_verdict(Vec3d site, double radius, const Grid<std::uint8_t>& holes_before, const Grid<std::uint8_t>& holes_after,
                         const Grid<std::uint8_t>& mask_before, const Grid<std::uint8_t>& mask_after);

}  // namespace liveset
