// Slice orientation, pixel mapping, texels and zero contours.
#include "liveset/render/slice_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace liveset::render {

std::string to_string(SliceAxis axis) {
    switch (axis) {
        case SliceAxis::kAxial: return "axial";
        case SliceAxis::kCoronal: return "coronal";
        case SliceAxis::kSagittal: return "sagittal";
    }
    return "?";
}

namespace {

// The lattice axis whose direction is closest to world axis `w`, and whether it points along +w.
int closest_axis(const Lattice& l, int w, bool& positive, int exclude_a = -1, int exclude_b = -1) {
    const Mat3d& d = l.direction();
    int best = -1;
    double best_abs = -1.0;
    for (int a = 0; a < 3; ++a) {
        if (a == exclude_a || a == exclude_b) continue;
        const double c = d[static_cast<std::size_t>(w * 3 + a)];
        if (std::abs(c) > best_abs) {
            best_abs = std::abs(c);
            best = a;
            positive = c > 0;
        }
    }
    return best;
}

}  // namespace

SliceGeometry slice_geometry(const Lattice& lattice, SliceAxis view) {
    // World (LPS) axis cut by the view, and the world axes (with direction) along screen right/up.
    int normal_w = 2, right_w = 0, up_w = 1;
    bool right_positive = true, up_positive = false;  // axial: right = +x (patient left), up = -y (anterior)
    if (view == SliceAxis::kCoronal) {
        normal_w = 1, right_w = 0, up_w = 2, right_positive = true, up_positive = true;
    } else if (view == SliceAxis::kSagittal) {
        normal_w = 0, right_w = 1, up_w = 2, right_positive = true, up_positive = true;  // right = posterior
    }
    SliceGeometry g;
    g.view = view;
    bool pos = true;
    g.normal_axis = closest_axis(lattice, normal_w, pos);
    g.u_axis = closest_axis(lattice, right_w, pos, g.normal_axis);
    g.u_flip = pos != right_positive;
    g.v_axis = closest_axis(lattice, up_w, pos, g.normal_axis, g.u_axis);
    g.v_flip = pos != up_positive;
    const Vec3i d = lattice.dims();
    const Vec3d s = lattice.spacing();
    g.width = d[g.u_axis];
    g.height = d[g.v_axis];
    g.slices = d[g.normal_axis];
    g.u_mm = s[g.u_axis];
    g.v_mm = s[g.v_axis];
    return g;
}

glm::dvec2 SliceGeometry::to_uv(Vec3d index) const {
    const double a = index[u_axis], b = index[v_axis];
    return {(u_flip ? width - 1 - a : a) + 0.5, (v_flip ? height - 1 - b : b) + 0.5};
}

Vec3d SliceGeometry::to_index(glm::dvec2 uv, int slice) const {
    Vec3d p{};
    const double a = uv.x - 0.5, b = uv.y - 0.5;
    p[u_axis] = u_flip ? width - 1 - a : a;
    p[v_axis] = v_flip ? height - 1 - b : b;
    p[normal_axis] = slice;
    return p;
}

int SliceGeometry::slice_of(Vec3d index) const {
    return std::clamp(static_cast<int>(std::lround(index[normal_axis])), 0, slices - 1);
}

Vec3i SliceGeometry::voxel(int column, int row, int slice) const {
    Vec3i p{};
    p[u_axis] = u_flip ? width - 1 - column : column;
    p[v_axis] = v_flip ? height - 1 - row : row;
    p[normal_axis] = slice;
    return p;
}

SliceViewport SliceViewport::fit(const SliceGeometry& g, int pane_width, int pane_height) {
    SliceViewport v;
    v.geometry = g;
    v.pane_width = std::max(pane_width, 1);
    v.pane_height = std::max(pane_height, 1);
    v.centre_uv = {0.5 * g.width, 0.5 * g.height};
    return v;
}

double SliceViewport::pixels_per_mm() const {
    const double w_mm = geometry.width * geometry.u_mm, h_mm = geometry.height * geometry.v_mm;
    return 0.98 * zoom * std::min(pane_width / w_mm, pane_height / h_mm);
}

glm::dvec2 SliceViewport::to_pixel(glm::dvec2 uv) const {
    const double s = pixels_per_mm();
    return {0.5 * pane_width + (uv.x - centre_uv.x) * geometry.u_mm * s,
            0.5 * pane_height - (uv.y - centre_uv.y) * geometry.v_mm * s};
}

glm::dvec2 SliceViewport::to_uv(glm::dvec2 pixel) const {
    const double s = pixels_per_mm();
    return {centre_uv.x + (pixel.x - 0.5 * pane_width) / (geometry.u_mm * s),
            centre_uv.y - (pixel.y - 0.5 * pane_height) / (geometry.v_mm * s)};
}

std::vector<std::uint8_t> slice_texels(const Grid<float>& unit_image, const SliceGeometry& g, int slice) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height));
    slice = std::clamp(slice, 0, g.slices - 1);
    for (int r = 0; r < g.height; ++r)
        for (int c = 0; c < g.width; ++c) {
            const float v = unit_image(g.voxel(c, r, slice));
            out[static_cast<std::size_t>(r) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(c)] =
                static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(v, 0.0f, 1.0f)));
        }
    return out;
}

std::vector<float> phi_slice(const Grid<float>& phi, const SliceGeometry& g, int slice) {
    return slice_values(g, slice, [&](Vec3i v) { return phi(v); });
}

std::vector<glm::dvec2> zero_contour(const Grid<float>& phi, const SliceGeometry& g, int slice) {
    if (slice < 0 || slice >= g.slices) return {};
    return zero_contour(phi_slice(phi, g, slice), g);
}

std::vector<glm::dvec2> zero_contour(std::span<const float> values, const SliceGeometry& g) {
    std::vector<glm::dvec2> segments;
    if (values.size() != static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height))
        throw std::invalid_argument("zero_contour: one value per texel of the slice is needed");
    const auto at = [&](int c, int r) {
        return static_cast<double>(values[static_cast<std::size_t>(r) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(c)]);
    };
    const auto crossing = [](glm::dvec2 a, double fa, glm::dvec2 b, double fb) {
        const double t = fa / (fa - fb);
        return a + t * (b - a);
    };
    for (int r = 0; r + 1 < g.height; ++r)
        for (int c = 0; c + 1 < g.width; ++c) {
            // Corners counter-clockwise from the bottom-left; voxel centres at +0.5.
            const glm::dvec2 p[4] = {{c + 0.5, r + 0.5}, {c + 1.5, r + 0.5}, {c + 1.5, r + 1.5}, {c + 0.5, r + 1.5}};
            const double f[4] = {at(c, r), at(c + 1, r), at(c + 1, r + 1), at(c, r + 1)};
            int code = 0;
            for (int k = 0; k < 4; ++k) code |= (f[k] < 0.0) << k;
            if (code == 0 || code == 15) continue;
            glm::dvec2 e[4];  // crossing on edge k (corner k -> k+1), where the signs differ
            for (int k = 0; k < 4; ++k) {
                const int n = (k + 1) % 4;
                if ((f[k] < 0.0) != (f[n] < 0.0)) e[k] = crossing(p[k], f[k], p[n], f[n]);
            }
            const auto add = [&](int a, int b) {
                segments.push_back(e[a]);
                segments.push_back(e[b]);
            };
            const bool centre_inside = (f[0] + f[1] + f[2] + f[3]) < 0.0;
            switch (code) {
                case 1: case 14: add(3, 0); break;
                case 2: case 13: add(0, 1); break;
                case 4: case 11: add(1, 2); break;
                case 8: case 7: add(2, 3); break;
                case 3: case 12: add(3, 1); break;
                case 6: case 9: add(0, 2); break;
                case 5:  // corners 0 and 2 inside
                    if (centre_inside) { add(0, 1); add(2, 3); } else { add(3, 0); add(1, 2); }
                    break;
                case 10:  // corners 1 and 3 inside
                    if (centre_inside) { add(3, 0); add(1, 2); } else { add(0, 1); add(2, 3); }
                    break;
                default: break;
            }
        }
    return segments;
}

}  // namespace liveset::render
