// Slice views as ITK-SNAP shows them, independent of OpenGL: which lattice axis each of the axial,
// coronal and sagittal views cuts and which runs along the screen (chosen from the direction
// cosines, so a sagittally stored image still shows upright), radiological orientation (axial and
// coronal: the patient's right on the screen's left; axial: anterior up; sagittal: anterior left,
// superior up), square millimetres on screen for anisotropic voxels, pane pixel <-> voxel mapping,
// the slice's intensities as texels and the zero contour of φ by marching squares.
#pragma once

#include <glm/glm.hpp>
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset::render {

enum class SliceAxis { kAxial, kCoronal, kSagittal };
std::string to_string(SliceAxis axis);

// Slice texel space ("uv"): u runs to the screen's right, v up; texel (c, r) covers
// [c, c+1] x [r, r+1], so a voxel centre sits at (c + 0.5, r + 0.5).
struct SliceGeometry {
    SliceAxis view = SliceAxis::kAxial;
    int normal_axis = 2;           // lattice axis the slices are taken along
    int u_axis = 0, v_axis = 1;    // lattice axes along the screen's right and up
    bool u_flip = false;           // screen right runs towards lower lattice index
    bool v_flip = false;
    int width = 1, height = 1;     // texels
    int slices = 1;
    double u_mm = 1.0, v_mm = 1.0;  // texel size

    glm::dvec2 to_uv(Vec3d index) const;             // continuous index -> slice texel space
    Vec3d to_index(glm::dvec2 uv, int slice) const;  // and back, on slice `slice`
    int slice_of(Vec3d index) const;                 // nearest slice, clamped
    // Lattice point of texel (c, r) on `slice`.
    Vec3i voxel(int column, int row, int slice) const;
};

SliceGeometry slice_geometry(const Lattice& lattice, SliceAxis view);

// The slice's texel rectangle fitted into a pane (pixels, top-left origin), optionally zoomed
// around a centre; maps between pane pixels and texel space.
struct SliceViewport {
    SliceGeometry geometry;
    int pane_width = 1, pane_height = 1;
    double zoom = 1.0;
    glm::dvec2 centre_uv{0.0};  // texel-space point at the pane's centre (default: the slice's centre)

    static SliceViewport fit(const SliceGeometry& g, int pane_width, int pane_height);
    double pixels_per_mm() const;
    glm::dvec2 to_pixel(glm::dvec2 uv) const;
    glm::dvec2 to_uv(glm::dvec2 pixel) const;
};

// Grey texels (row 0 at the bottom) of `unit_image` (values in [0, 1]) on `slice`.
std::vector<std::uint8_t> slice_texels(const Grid<float>& unit_image, const SliceGeometry& g, int slice);

// `at(voxel)` for every texel of `slice` (clamped), one value per texel in the order of slice_texels.
template <class At>
std::vector<float> slice_values(const SliceGeometry& g, int slice, const At& at) {
    std::vector<float> out(static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height));
    slice = std::clamp(slice, 0, g.slices - 1);
    for (int r = 0; r < g.height; ++r)
        for (int c = 0; c < g.width; ++c)
            out[static_cast<std::size_t>(r) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(c)] = at(g.voxel(c, r, slice));
    return out;
}
// φ on `slice` (clamped): slice_values of φ.
std::vector<float> phi_slice(const Grid<float>& phi, const SliceGeometry& g, int slice);

// Segments (pairs of end points, texel space) of φ = 0 on `slice`, by marching squares between
// voxel centres; φ < 0 inside, as the mesher. Empty for a slice outside the lattice.
std::vector<glm::dvec2> zero_contour(const Grid<float>& phi, const SliceGeometry& g, int slice);
// The same from a slice's values (phi_slice's order; a field other than the lattice's own, e.g.
// a coarse run's previewed on the image's grid). Throws std::invalid_argument unless there is
// one value per texel.
std::vector<glm::dvec2> zero_contour(std::span<const float> values, const SliceGeometry& g);

}  // namespace liveset::render
