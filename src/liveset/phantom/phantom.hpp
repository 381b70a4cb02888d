// Synthetic T1-weighted MR phantom of a folded cortex with exact ground truth: a white-matter (WM)
// core whose surface carries gyri and sulci, a grey-matter (GM) shell 2.5-4 mm thick following the
// folds, cerebrospinal fluid (CSF) around it and in the sulci, dark background outside. The image
// has partial-volume edges, a light blur, a smooth multiplicative bias field and Rician (or
// Gaussian) noise. The bias is strong enough that the global GM intensity window (gm_window())
// perforates the thresholded GM shell near `weak_spots` while leaving it intact elsewhere: the
// situation the paper's agent swarms repair. Deterministic: same options -> same bytes, for any
// thread count. Standard library + oneTBB only.
//
// Model (x in mm, volume centred on the origin, L = size * spacing / 2, LPS axes: +z superior,
// a = (0.84, 1, 0.80) the brain's aspect ratios, u = x / |x|):
//   WM      F(x) = |x / a| - R0 - A tanh((n(u) - 0.4) / 0.35) < 0. n(u) = sum of 24 plane waves
//           sqrt(2/24) cos(k_j . R u + phi_j), random directions, |k_j| = 2 pi / lambda * [0.85, 1.15]:
//           a labyrinth of gyri (n > 0.4: WM blades up to R0 + A) and sulci (down to R0 - A).
//           R = 0.88 L - c is the pial crest radius, A = 0.13 R * fold_depth, R0 = R - t_max - A,
//           lambda = max(0.24 R, t_min + t_max + 4.5 spacing).
//   d(x)    signed Euclidean distance (mm) to F = 0, negative inside: foot points on the surface by
//           Newton projection from the voxels next to it, spread by jump flooding.
//   GM      0 <= d < t(u): t in [gm_thickness_min_mm, gm_thickness_max_mm] (never below 2.5
//           voxels), a smooth function of direction (6 long plane waves).
//   CSF     min(d - t - c, e(x)) < 0 outside GM: c = csf_thickness_mm (at least 2 voxels), e the
//           signed distance to the "skull" ellipsoid of semi-axes (R + c) a. CSF covers the gyral
//           crowns by at least c and fills the sulci up to the skull; background outside.
//   Topology The GM truth is one closed shell around the WM (components 1, cavities 1, genus 0,
//           euler 4 as mask_topology reads it), so `holes` counts a segmentation's perforations
//           and nothing of the anatomy: where GM banks meet across a narrow sulcus, the CSF under
//           the bridge (any voxel whose outward ray passes a cell with a pial-body corner, repeated
//           until stable, plus enclosed pockets) becomes pure GM; then the pial body and the WM
//           are regrown from the centre by simple points only (topology_growth.hpp), the WM kept a
//           voxel inside the body; the few voxels refused take the outer tissue's label. Voxels
//           next to such changes get crisp (label) intensities instead of partial volume.
//   Image   I0 = sum over tissues of volume fraction * nominal value (WM 800, GM 530, CSF 220,
//           background 0); fractions from the partial-volume ramp S(s) = clamp(1/2 - s/spacing, 0, 1)
//           across each interface; then a Gaussian blur of `blur` voxels.
//   Bias    b(x) = 1 + bias * (1 - prod_k (1 - w_k G_k(x))), G_k = exp(-|x - c_k|^2 / (2 s_k^2)):
//           k = 0 broad (w 0.15, s 0.6 L, on the skull's superior pole): a visible gradient;
//           k = 1 local (w 1, s 0.13 L, superior-posterior, at the pial crest level);
//           k = 2 local (w 1, s 0.11 L, left-anterior-superior, at the pial crest level).
//           So 1 <= b <= 1 + bias, b ~ 1 inferiorly. Where b > ~1.3 the GM (530 b) rises above
//           the window's top (665) and the thresholded shell is perforated; with the default
//           bias (0.65) a threshold level set leaves one perforation at each weak spot.
//   Noise   Rician |b I0 + sigma (n1 + i n2)| (or Gaussian b I0 + sigma n1), sigma = noise * 800,
//           n1, n2 by Box-Muller from a splitmix64 hash of (seed, voxel index).
// The defaults (128^3, 1 mm) take under a second on one core. Perforations at both weak spots
// hold for sizes 64-128 at 1 mm (tested at 64 and 96). A threshold level set (paper Eq. 2-3,
// mu/epsilon from gm_window(), n = 4, curvature weight 0.1) grown from the seeds reaches Dice
// ~0.955 (64^3), 0.963 (96^3) and 0.974 (128^3) against the GM truth at the default options, with
// holes = 2 (one perforation per weak spot).
#pragma once

#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct PhantomOptions {
    int size = 128;                    // voxels per axis (cube), 32..512
    double spacing_mm = 1.0;           // isotropic voxel size, (0, 10]
    std::uint64_t seed = 1;            // noise seed
    std::uint64_t anatomy_seed = 1;    // folds and thickness pattern
    double noise = 0.03;               // noise sigma as a fraction of the WM intensity, [0, 0.5]
    bool rician = true;                // magnitude (Rician) noise; false: additive Gaussian
    double bias = 0.65;                // peak relative gain of the bias field: b in [1, 1 + bias], [0, 1]
    double fold_depth = 1.0;           // scales the fold amplitude (0: smooth ellipsoid), [0, 1.5]
    double gm_thickness_min_mm = 2.5;  // GM thickness range (clamped to >= 2.5 voxels), (0, 10]
    double gm_thickness_max_mm = 4.0;
    double csf_thickness_mm = 3.0;     // minimum CSF layer over the gyri (>= 2 voxels), [0, 10]
    double blur = 0.4;                 // Gaussian blur sigma in voxels (0: none), [0, 2]
};

// Throws std::invalid_argument with a one-line message when an option is out of range or not finite.
void validate(const PhantomOptions& options);

// Tissue labels (BrainWeb-style crisp labels).
inline constexpr std::uint8_t kBackground = 0;
inline constexpr std::uint8_t kCsf = 1;
inline constexpr std::uint8_t kGreyMatter = 2;
inline constexpr std::uint8_t kWhiteMatter = 3;

struct Phantom {
    Grid<float> image;                 // raw intensities (scanner-like units, WM ~800)
    Grid<std::uint8_t> labels;         // 0 bg, 1 CSF, 2 GM, 3 WM (crisp, at voxel centres)
    Grid<std::uint8_t> truth;          // GM mask (labels == 2), 0/1
    Grid<float> bias_field;            // the multiplicative field applied
    std::vector<Vec3i> seeds;          // 3-6 voxels deep in GM (26-neighbours GM), in the window, low bias
    std::vector<Vec3i> weak_spots;     // GM voxels where each bias bump is strongest (holes expected)
    float gm_intensity = 0, wm_intensity = 0, csf_intensity = 0;  // nominal (no bias, no noise)
    float background_intensity = 0;
};

// The global GM intensity window of the threshold speed (paper Eq. 3):
// [gm - (gm - csf) / 2, gm + (wm - gm) / 2], i.e. mu = centre, epsilon = half width.
struct IntensityWindow {
    float lo = 0, hi = 0;
    bool contains(float v) const { return v >= lo && v <= hi; }
    float centre() const { return 0.5f * (lo + hi); }
    float half_width() const { return 0.5f * (hi - lo); }
};
IntensityWindow gm_window(const Phantom& phantom);

// Builds the phantom; validates the options first. Lattice: size^3, isotropic spacing, origin such
// that the volume is centred on (0,0,0) mm, identity direction.
Phantom make_phantom(const PhantomOptions& options = {});

}  // namespace liveset
