// Bias-field (intensity inhomogeneity) correction: ITK's N4 (Tustison et al. 2010) run on a shrunk
// copy of the image, its smooth log field evaluated at full resolution and divided out. This header
// includes no ITK (the edge library liveset_preprocess keeps ITK private).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

// N4's parameters. Standard settings, not tuned to a scan: ITK's own N4 default convergence
// (1e-3), 3D Slicer's N4ITK default of 3 fitting levels, and the literature's B-spline mesh elements
// of ~200 mm, Wiener noise 0.01, deconvolution FWHM 0.15 and 200 histogram bins (Tustison et al.
// 2010), on a 6 mm grid. Until session 47 they were ANTs' 4 levels x 50 iterations, convergence
// 1e-6 (never reached: every run did all 200 iterations) on a 4 mm grid: 9-16x the time, and on
// BrainWeb a field that left the tissue classes wider (docs/BENCHMARKS.md, session 47).
struct BiasCorrectionOptions {
    // Target voxel size of the shrunk grid N4 runs on: the shrink factor along an axis is
    // round(shrink_mm / spacing), at least 1 (6 for 1 mm voxels, 1 for voxels of 6 mm or more).
    // The field is smooth (the third level's mesh elements are 27-45 mm on a head), so a 6 mm grid
    // still samples each of them 4-8 times a side.
    double shrink_mm = 6.0;
    int levels = 3;              // fitting levels; the B-spline mesh doubles at each
    int iterations = 50;         // maximum iterations per level
    double convergence = 1e-3;   // stop a level when the field's change (N4's CV measure) falls below
    // Length of one B-spline mesh element at the first level: an axis spanning L mm gets
    // ceil(L / spline_distance_mm) elements (at least 1), i.e. that many + 3 control points (cubic).
    double spline_distance_mm = 200.0;
    double wiener_noise = 0.01;  // Wiener deconvolution noise of N4's histogram sharpening
    double fwhm = 0.15;          // FWHM of the Gaussian bias-field blur of the log-intensity histogram
    int histogram_bins = 200;
    // Each sample N4 fits is the median of the fit voxels in its 3×3×3 neighbourhood, not the bare
    // voxel: robust to noise (a noisy scan without bias otherwise gets a strong false field).
    bool denoise = true;

    // Throws std::invalid_argument (one line) on a non-finite or out-of-range value.
    void validate() const;
};

struct BiasCorrectionReport {
    double ms = 0.0;             // whole call (mask, shrink, N4, full-resolution field, division)
    double n4_ms = 0.0;          // of which N4 on the shrunk grid
    Vec3i shrink_factors{1, 1, 1};
    Vec3i shrunk_dims{0, 0, 0};
    Vec3i control_points{0, 0, 0};  // first-level B-spline lattice (mesh elements + 3)
    bool otsu_mask = false;      // the fit mask came from Otsu's threshold (no mask given)
    std::size_t mask_voxels = 0; // full-resolution voxels of the fit mask (mask and intensity > 0)
    std::vector<int> level_iterations;  // iterations N4 ran at each level (empty: image flat in the mask)
    double final_convergence = 0.0;     // N4's convergence measure at its last iteration
    // Range of the estimated multiplicative field inside the fit mask (corrected = image / field),
    // normalised to a geometric mean of 1 there.
    double field_min = 1.0, field_max = 1.0;
    bool interrupted = false;    // `interrupt` turned true during N4: the image came back uncorrected
};

// The image divided by N4's estimate of its multiplicative bias field.
//  - The field is fitted inside `mask` (non-zero voxels; same lattice as the image) or, without
//    one, inside Otsu's foreground (otsu_foreground below); voxels <= 0 never enter the fit (N4
//    works on log intensities).
//  - N4 runs on the image subsampled by the shrink factors (voxels 0, f, 2f, ... along each axis,
//    the last sample at or past the image's end so the shrunk grid's span covers the image). Its
//    B-spline control lattice is then evaluated at every full-resolution voxel (exact, no
//    resampling of the field) and normalised to mean log 0 inside the fit mask, so the corrected
//    image keeps the input's intensity scale there.
//  - Every voxel is divided by the field (a smooth positive function), outside the mask too: zeros
//    stay zero, negative voxels stay negative, no NaN. An image that is constant in the mask is
//    returned unchanged (field 1).
//  - Deterministic whatever the thread count, and within TBB's allowed parallelism (--threads):
//    ITK's filters inside N4 run a fixed number of work units as TBB tasks (ITK's scattered-data
//    B-spline fit sums one partial lattice per work unit, so a count that followed the threads
//    would change its rounding); the full-resolution field (bspline_field.hpp) and the division are
//    per voxel. The first call registers, for the rest of the process, the ITK object factory that
//    gives every ITK filter created after it that threader.
//  - N4 works in index units; millimetres only pick the shrink factors and the control points
//    (with a margin at rounding boundaries), so the same data stored with a voxel size a few ulps
//    apart (NIfTI's float, MINC's double) gets the same bits.
//  - `interrupt` (e.g. Ctrl-C) is polled at every N4 iteration; when it turns true N4 stops and the
//    input comes back unchanged with report->interrupted set.
// Throws std::invalid_argument (one line) on bad options, an empty image or an axis of < 2 voxels,
// NaN/infinite voxels, a mask on another lattice, a mask with no voxel > 0, or one too small to
// leave a voxel on the shrunk grid.
Grid<float> correct_bias(const Grid<float>& image, const Grid<std::uint8_t>* mask,
                         const BiasCorrectionOptions& options = {}, BiasCorrectionReport* report = nullptr,
                         const std::atomic<bool>* interrupt = nullptr);

// Otsu's threshold (maximal between-class variance) over a 256-bin histogram of the image's values
// between its minimum and maximum; returns the lower edge of the upper class's first bin, in image
// units. Throws std::invalid_argument on an empty image or a non-finite voxel; a flat image gives
// its value.
double otsu_threshold(const Grid<float>& image);
// Voxels >= otsu_threshold (the head or brain against a dark background), 1 inside, 0 outside.
Grid<std::uint8_t> otsu_foreground(const Grid<float>& image);

}  // namespace liveset
