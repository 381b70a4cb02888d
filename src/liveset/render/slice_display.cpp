// Window/level, overlay texels, zoom and pan, orientation letters and cursor coordinates.
#include "liveset/render/slice_display.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "liveset/segment/coarse_start.hpp"
#include "liveset/segment/intensity.hpp"

namespace liveset::render {

DisplayWindow DisplayWindow::from_level_width(double level, double width) { return {level - 0.5 * width, level + 0.5 * width}; }

std::uint8_t DisplayWindow::grey(double raw) const {
    const double t = std::clamp((raw - low) / (high - low), 0.0, 1.0);
    return static_cast<std::uint8_t>(std::lround(255.0 * t));
}

void DisplayWindow::validate() const {
    if (!std::isfinite(low) || !std::isfinite(high)) throw std::invalid_argument("the display window must be finite");
    if (!(high > low)) throw std::invalid_argument("the display window's high must be above its low");
}

DisplayWindow percentile_window(const Grid<float>& image, const Grid<std::uint8_t>* roi, double low_percent, double high_percent) {
    ScaleOptions o;
    o.low_percentile = low_percent;
    o.high_percentile = high_percent;
    try {
        const IntensityScale s = robust_scale(image, roi, o);
        return {s.low, s.high};
    } catch (const std::invalid_argument&) {  // flat (or empty ROI): centre a unit window on a value
        const double v = image.size() ? image.values().front() : 0.0;
        return {v - 0.5, v + 0.5};
    }
}

DisplayWindow preset_window(std::string_view preset, const Grid<float>& image, const Grid<std::uint8_t>* roi) {
    if (preset == "auto") return percentile_window(image, roi, 1.0, 99.0);
    if (preset == "minmax") return percentile_window(image, nullptr, 0.0, 100.0);
    if (preset == "narrow") return percentile_window(image, roi, 5.0, 95.0);
    throw std::invalid_argument("unknown window preset \"" + std::string(preset) + "\" (auto, minmax, narrow)");
}

std::vector<std::uint8_t> window_texels(const Grid<float>& image, const SliceGeometry& g, int slice, const DisplayWindow& window) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height));
    slice = std::clamp(slice, 0, g.slices - 1);
    for (int r = 0; r < g.height; ++r)
        for (int c = 0; c < g.width; ++c)
            out[static_cast<std::size_t>(r) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(c)] =
                window.grey(image(g.voxel(c, r, slice)));
    return out;
}

const char* to_string(RoiStyle style) {
    switch (style) {
        case RoiStyle::kOff: return "off";
        case RoiStyle::kOutline: return "outline";
        case RoiStyle::kTint: return "tint";
    }
    return "?";
}

std::optional<RoiStyle> roi_style_from_name(std::string_view name) {
    if (name == "off") return RoiStyle::kOff;
    if (name == "outline") return RoiStyle::kOutline;
    if (name == "tint") return RoiStyle::kTint;
    return std::nullopt;
}

namespace {

// Straight-alpha "over": colour `c` with opacity `a` on top of texel `px`.
void over(std::uint8_t* px, const std::array<std::uint8_t, 3>& c, float a) {
    if (a <= 0.0f) return;
    a = std::min(a, 1.0f);
    if (px[3] == 0) {  // nothing below
        px[0] = c[0], px[1] = c[1], px[2] = c[2];
        px[3] = static_cast<std::uint8_t>(std::lround(255.0f * a));
        return;
    }
    const float below = px[3] / 255.0f, out = a + below * (1.0f - a);
    for (int k = 0; k < 3; ++k)
        px[k] = static_cast<std::uint8_t>(std::lround((c[static_cast<std::size_t>(k)] * a + px[k] * below * (1.0f - a)) / out));
    px[3] = static_cast<std::uint8_t>(std::lround(255.0f * out));
}

}  // namespace

std::vector<float> upsampled_phi_slice(const Grid<float>& coarse_phi, const SliceGeometry& g, int slice) {
    return slice_values(g, slice, [&](Vec3i v) { return upsampled_phi(coarse_phi, v); });
}

std::vector<std::uint8_t> overlay_texels(const SliceGeometry& g, int slice, const OverlayStyle& style, std::span<const float> phi,
                                         const Grid<std::uint8_t>* roi, const Grid<float>* unit_image,
                                         const ThresholdParams* params) {
    const auto w = static_cast<std::size_t>(g.width), h = static_cast<std::size_t>(g.height);
    if (!phi.empty() && phi.size() != w * h) throw std::invalid_argument("overlay_texels: one φ value per texel of the slice is needed");
    std::vector<std::uint8_t> out(4 * w * h, 0);
    slice = std::clamp(slice, 0, g.slices - 1);
    std::vector<std::uint8_t> in_roi(w * h, 1);  // the ROI on this slice (all 1 without one)
    if (roi)
        for (int r = 0; r < g.height; ++r)
            for (int c = 0; c < g.width; ++c) in_roi[static_cast<std::size_t>(r) * w + static_cast<std::size_t>(c)] = (*roi)(g.voxel(c, r, slice)) != 0;
    const bool preview = style.preview && unit_image && params, fill = !phi.empty() && style.label_opacity > 0.0f;
    const auto roi_at = [&](int c, int r) {
        return c >= 0 && r >= 0 && c < g.width && r < g.height && in_roi[static_cast<std::size_t>(r) * w + static_cast<std::size_t>(c)];
    };
    for (int r = 0; r < g.height; ++r)
        for (int c = 0; c < g.width; ++c) {
            const std::size_t k = static_cast<std::size_t>(r) * w + static_cast<std::size_t>(c);
            std::uint8_t* px = &out[4 * k];
            const bool inside_roi = in_roi[k] != 0;
            if (!(preview && inside_roi) && !fill && !(roi && inside_roi && style.roi != RoiStyle::kOff)) continue;
            const Vec3i v = g.voxel(c, r, slice);
            // D < 0 exactly where |µ - I| < ε (D = (r - 1) / (r + 1), r = (|µ - I| / ε)^n): pow only there.
            if (preview && inside_roi && std::abs(params->mu - (*unit_image)(v)) < params->epsilon) {
                const double d = threshold_term((*unit_image)(v), *params);
                if (d < 0.0) over(px, style.preview_colour, static_cast<float>(-d) * style.preview_opacity);
            }
            if (fill && phi[k] < 0.0f) over(px, style.label_colour, style.label_opacity);
            if (roi && inside_roi && style.roi == RoiStyle::kTint) over(px, style.roi_colour, style.roi_tint_opacity);
            if (roi && inside_roi && style.roi == RoiStyle::kOutline &&
                (!roi_at(c - 1, r) || !roi_at(c + 1, r) || !roi_at(c, r - 1) || !roi_at(c, r + 1)))
                over(px, style.roi_colour, 1.0f);
        }
    return out;
}

SliceViewport zoom_about(SliceViewport vp, glm::dvec2 pixel, double factor) {
    const glm::dvec2 anchor = vp.to_uv(pixel);
    vp.zoom *= factor;
    // to_uv(pixel) = centre + offset / scale: keep it at `anchor` under the new scale.
    vp.centre_uv += anchor - vp.to_uv(pixel);
    return vp;
}

SliceViewport pan_by(SliceViewport vp, glm::dvec2 delta) {
    vp.centre_uv -= vp.to_uv(delta + glm::dvec2(0.5 * vp.pane_width, 0.5 * vp.pane_height)) - vp.centre_uv;
    return vp;
}

char direction_letter(Vec3d d) {
    const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    if (ax >= ay && ax >= az) return d.x > 0 ? 'L' : 'R';
    if (ay >= az) return d.y > 0 ? 'P' : 'A';
    return d.z > 0 ? 'S' : 'I';
}

EdgeLetters edge_letters(const Lattice& lattice, const SliceGeometry& g) {
    const Mat3d& m = lattice.direction();
    const auto column = [&](int axis, bool flip) {
        const double s = flip ? -1.0 : 1.0;
        const auto a = static_cast<std::size_t>(axis);
        return Vec3d{s * m[a], s * m[3 + a], s * m[6 + a]};
    };
    const Vec3d right = column(g.u_axis, g.u_flip), up = column(g.v_axis, g.v_flip);
    return {direction_letter(-1.0 * right), direction_letter(right), direction_letter(up), direction_letter(-1.0 * up)};
}

Vec3i one_based(Vec3i voxel) { return {voxel.x + 1, voxel.y + 1, voxel.z + 1}; }

Vec3d lps_of(const Lattice& lattice, Vec3i voxel) { return lattice.to_world(voxel.cast<double>()); }

Vec3d ras_of(const Lattice& lattice, Vec3i voxel) {
    const Vec3d p = lps_of(lattice, voxel);
    return {-p.x, -p.y, p.z};
}

std::optional<Vec3i> voxel_from(const Lattice& lattice, Vec3d value, CursorUnits units) {
    Vec3d index{};
    switch (units) {
        case CursorUnits::kVoxel1: index = {value.x - 1.0, value.y - 1.0, value.z - 1.0}; break;
        case CursorUnits::kLps: index = lattice.to_index(value); break;
        case CursorUnits::kRas: index = lattice.to_index({-value.x, -value.y, value.z}); break;
    }
    if (!std::isfinite(index.x) || !std::isfinite(index.y) || !std::isfinite(index.z)) return std::nullopt;
    const Vec3i v{static_cast<int>(std::lround(index.x)), static_cast<int>(std::lround(index.y)), static_cast<int>(std::lround(index.z))};
    if (std::abs(index.x) > 1e9 || std::abs(index.y) > 1e9 || std::abs(index.z) > 1e9 || !lattice.contains(v)) return std::nullopt;
    return v;
}

std::optional<Vec3d> parse_triple(std::string_view text) {
    std::string s(text);
    std::replace(s.begin(), s.end(), ',', ' ');
    double v[3];
    const char* p = s.c_str();
    for (double& x : v) {
        char* end = nullptr;
        x = std::strtod(p, &end);
        if (end == p || !std::isfinite(x)) return std::nullopt;
        p = end;
    }
    while (*p == ' ' || *p == '\t') ++p;
    if (*p != '\0') return std::nullopt;
    return Vec3d{v[0], v[1], v[2]};
}

}  // namespace liveset::render
