// What a slice pane shows besides its geometry, independent of OpenGL: the display window
// (window/level: raw intensity -> grey, automatic from the histogram's percentiles, presets), the
// RGBA overlay texels (filled segmentation with an opacity, the ROI as outline or tint, the
// threshold-speed preview where the data term D < 0 lets the front grow), zoom about a pane pixel
// and pan, the orientation letters on a pane's edges from the image's direction cosines, and the
// cursor's coordinates (1-based voxels as ITK-SNAP shows them, millimetres in LPS and RAS).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/render/slice_geometry.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset::render {

// Window/level in raw intensities: `low` maps to black, `high` to white, linear between.
struct DisplayWindow {
    double low = 0.0;
    double high = 1.0;
    double level() const { return 0.5 * (low + high); }
    double width() const { return high - low; }
    static DisplayWindow from_level_width(double level, double width);
    std::uint8_t grey(double raw) const;  // round(255 clamp((raw - low) / (high - low), 0, 1))
    void validate() const;                // throws std::invalid_argument unless finite and high > low
};

// The window from the `low_percent`..`high_percent` percentiles of the image (inside `roi`, when
// given); a flat image gets a unit-wide window around its value.
DisplayWindow percentile_window(const Grid<float>& image, const Grid<std::uint8_t>* roi, double low_percent,
                                double high_percent);

// Named windows offered by the panel and scripts: "auto" (1st-99th percentile inside the ROI, the
// default), "minmax" (the whole range), "narrow" (5th-95th percentile inside the ROI). Throws
// std::invalid_argument for another name.
DisplayWindow preset_window(std::string_view preset, const Grid<float>& image, const Grid<std::uint8_t>* roi);
inline constexpr std::array<const char*, 3> kWindowPresets = {"auto", "minmax", "narrow"};

// Grey texels (row 0 at the bottom) of the raw `image` on `slice` through `window`.
std::vector<std::uint8_t> window_texels(const Grid<float>& image, const SliceGeometry& g, int slice, const DisplayWindow& window);

enum class RoiStyle { kOff, kOutline, kTint };
const char* to_string(RoiStyle style);
std::optional<RoiStyle> roi_style_from_name(std::string_view name);

struct OverlayStyle {
    float label_opacity = 0.35f;  // the segmentation (φ < 0) filled; 0: not drawn
    std::array<std::uint8_t, 3> label_colour{230, 60, 50};
    RoiStyle roi = RoiStyle::kOutline;
    std::array<std::uint8_t, 3> roi_colour{255, 210, 40};
    float roi_tint_opacity = 0.2f;  // RoiStyle::kTint: inside the ROI
    bool preview = false;           // the threshold-speed preview
    float preview_opacity = 0.6f;   // at D = -1 (µ itself); -D times this where -1 < D < 0
    std::array<std::uint8_t, 3> preview_colour{60, 140, 255};
};

// A coarse start's φ (coarse_start.hpp) previewed on `slice` of the image's grid: upsampled_phi at
// each texel's voxel, in phi_slice's order - negative exactly where upsample_inside puts its front
// (the fine start before the ROI, the voxels the image's data term refuses and the seeds' balls).
std::vector<float> upsampled_phi_slice(const Grid<float>& coarse_phi, const SliceGeometry& g, int slice);

// Straight-alpha RGBA texels (row 0 at the bottom) of the overlay on `slice`, layered (each
// "over" the one before): preview, label fill (where `phi`, the slice's values in phi_slice's
// order, is negative), ROI. The preview tints the voxels inside the ROI where D(I) < 0 for the
// normalised intensity I of `unit_image` - where the data term alone would expand the front
// (ThresholdSpeed: ∂φ/∂t = |∇φ| F, φ < 0 inside). Null or empty inputs skip their layer; a `phi`
// of another size throws std::invalid_argument.
std::vector<std::uint8_t> overlay_texels(const SliceGeometry& g, int slice, const OverlayStyle& style, std::span<const float> phi,
                                         const Grid<std::uint8_t>* roi, const Grid<float>* unit_image,
                                         const ThresholdParams* params);

// The viewport zoomed by `factor` so the texel-space point under pane pixel `pixel` stays there.
SliceViewport zoom_about(SliceViewport vp, glm::dvec2 pixel, double factor);
// The viewport's content moved by `delta` pane pixels (the point under p goes to p + delta).
SliceViewport pan_by(SliceViewport vp, glm::dvec2 delta);

// Anatomical letters at a pane's left, right, top and bottom edges: the patient direction (R, L,
// A, P, S, I) the screen's axes point to, from the lattice axis shown along each screen axis, its
// flip and its direction cosine (LPS world: +x left, +y posterior, +z superior).
struct EdgeLetters {
    char left = '?', right = '?', top = '?', bottom = '?';
};
EdgeLetters edge_letters(const Lattice& lattice, const SliceGeometry& g);
// The letter of the LPS world direction `d`'s largest component ('L' for +x, 'R' for -x, ...).
char direction_letter(Vec3d d);

// The cursor's coordinates: ITK-SNAP's 1-based voxels, millimetres in LPS (ITK's world) and RAS
// (NIfTI's scanner space: x and y negated).
Vec3i one_based(Vec3i voxel);
Vec3d lps_of(const Lattice& lattice, Vec3i voxel);
Vec3d ras_of(const Lattice& lattice, Vec3i voxel);
// The voxel nearest a point: from 1-based voxel numbers, LPS mm or RAS mm; nullopt outside.
enum class CursorUnits { kVoxel1, kLps, kRas };
std::optional<Vec3i> voxel_from(const Lattice& lattice, Vec3d value, CursorUnits units);
// Three numbers separated by spaces and/or commas ("12 40 7", "-3.5, 12, 40"); nullopt otherwise.
std::optional<Vec3d> parse_triple(std::string_view text);

}  // namespace liveset::render
