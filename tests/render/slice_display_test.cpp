// Slice display: zoom about a point keeps it fixed and pan moves it by the drag (analytic), window/
// level and percentiles (brute force), the overlay's layers (label fill opacity, ROI outline,
// speed preview exactly where D < 0), orientation letters from the direction cosines (and against
// nibabel's aff2axcodes), a coarse start's preview (its fill = upsample_inside), 1-based voxels and LPS/RAS millimetres (against nibabel's affine), and
// pixels of the rendered pane (headless EGL): grey from the window, overlay at opacity 0 and 1.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "liveset/io/image_io.hpp"
#include "liveset/render/slice_display.hpp"
#include "liveset/segment/coarse_start.hpp"
#include "liveset/render/slice_renderer.hpp"
#include "render/render_test_util.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

using render::SliceAxis;

TEST(SliceZoom, ZoomAboutAPixelKeepsTheTexelUnderIt) {
    const Lattice lat({60, 50, 30}, {0.8, 1.0, 2.0});
    for (const SliceAxis view : {SliceAxis::kAxial, SliceAxis::kCoronal, SliceAxis::kSagittal}) {
        render::SliceViewport vp = render::SliceViewport::fit(render::slice_geometry(lat, view), 300, 200);
        for (const glm::dvec2 pixel : {glm::dvec2(37.0, 150.5), glm::dvec2(250.0, 12.0), glm::dvec2(150.0, 100.0)}) {
            const glm::dvec2 before = vp.to_uv(pixel);
            const double s0 = vp.pixels_per_mm();
            vp = render::zoom_about(vp, pixel, 2.5);
            EXPECT_NEAR(vp.pixels_per_mm(), 2.5 * s0, 1e-12);
            const glm::dvec2 after = vp.to_uv(pixel);
            EXPECT_NEAR(after.x, before.x, 1e-9);
            EXPECT_NEAR(after.y, before.y, 1e-9);
            // Another pixel: its texel moved towards the anchor by the zoom factor (analytic).
            const glm::dvec2 q = pixel + glm::dvec2(40.0, -30.0);
            const glm::dvec2 uq = vp.to_uv(q);
            EXPECT_NEAR(uq.x - after.x, 40.0 / (vp.pixels_per_mm() * vp.geometry.u_mm), 1e-9);
            EXPECT_NEAR(uq.y - after.y, 30.0 / (vp.pixels_per_mm() * vp.geometry.v_mm), 1e-9);
        }
    }
}

TEST(SliceZoom, PanMovesThePointUnderThePointerByTheDrag) {
    const Lattice lat({40, 40, 10}, {1.0, 1.0, 4.0});
    render::SliceViewport vp = render::SliceViewport::fit(render::slice_geometry(lat, SliceAxis::kCoronal), 400, 300);
    vp = render::zoom_about(vp, {100.0, 80.0}, 3.0);
    const glm::dvec2 p{123.0, 77.0}, delta{31.0, -17.5};
    const glm::dvec2 uv = vp.to_uv(p);
    vp = render::pan_by(vp, delta);
    const glm::dvec2 moved = vp.to_uv(p + delta);
    EXPECT_NEAR(moved.x, uv.x, 1e-9);
    EXPECT_NEAR(moved.y, uv.y, 1e-9);
    // Pixel -> voxel after zoom and pan: the voxel centre's pixel maps back to that voxel.
    const Vec3i v{17, 3, 6};
    const glm::dvec2 px = vp.to_pixel(vp.geometry.to_uv(v.cast<double>()));
    const Vec3d back = vp.geometry.to_index(vp.to_uv(px), 3);
    EXPECT_NEAR(back.x, 17.0, 1e-9);
    EXPECT_NEAR(back.z, 6.0, 1e-9);
}

TEST(DisplayWindow, MapsIntensitiesLinearlyAndClamps) {
    const render::DisplayWindow w{20.0, 220.0};
    EXPECT_EQ(w.grey(20.0), 0);
    EXPECT_EQ(w.grey(220.0), 255);
    EXPECT_EQ(w.grey(-5.0), 0);
    EXPECT_EQ(w.grey(1000.0), 255);
    EXPECT_EQ(w.grey(120.0), 128);               // 127.5 rounds up
    EXPECT_EQ(w.grey(70.0), std::lround(255.0 * 50.0 / 200.0));
    const auto lw = render::DisplayWindow::from_level_width(w.level(), w.width());
    EXPECT_DOUBLE_EQ(lw.low, 20.0);
    EXPECT_DOUBLE_EQ(lw.high, 220.0);
    EXPECT_THROW((render::DisplayWindow{5.0, 5.0}.validate()), std::invalid_argument);
}

TEST(DisplayWindow, AutoIsTheFirstToNinetyNinthPercentileInsideTheRoi) {
    const Lattice lat({10, 10, 10});
    Grid<float> image(lat);
    Grid<std::uint8_t> roi(lat);
    for (PointIndex i = 0; i < image.size(); ++i) {
        image[i] = static_cast<float>((i * 7919) % 1000);  // a permutation of 0..999
        roi[i] = image[i] >= 500.0f;
    }
    // Brute force: sorted values inside the ROI, the order statistics around 1 % and 99 %.
    std::vector<float> in;
    for (PointIndex i = 0; i < image.size(); ++i)
        if (roi[i]) in.push_back(image[i]);
    std::sort(in.begin(), in.end());
    const auto w = render::preset_window("auto", image, &roi);
    const double n = static_cast<double>(in.size() - 1);
    EXPECT_GE(w.low, in[static_cast<std::size_t>(std::floor(0.01 * n))]);
    EXPECT_LE(w.low, in[static_cast<std::size_t>(std::ceil(0.01 * n))]);
    EXPECT_GE(w.high, in[static_cast<std::size_t>(std::floor(0.99 * n))]);
    EXPECT_LE(w.high, in[static_cast<std::size_t>(std::ceil(0.99 * n))]);
    const auto narrow = render::preset_window("narrow", image, &roi);
    EXPECT_GE(narrow.low, in[static_cast<std::size_t>(std::floor(0.05 * n))]);
    EXPECT_LE(narrow.low, in[static_cast<std::size_t>(std::ceil(0.05 * n))]);
    EXPECT_GE(narrow.high, in[static_cast<std::size_t>(std::floor(0.95 * n))]);
    EXPECT_LE(narrow.high, in[static_cast<std::size_t>(std::ceil(0.95 * n))]);
    const auto mm = render::preset_window("minmax", image, &roi);
    EXPECT_DOUBLE_EQ(mm.low, 0.0);
    EXPECT_DOUBLE_EQ(mm.high, 999.0);
    EXPECT_THROW(render::preset_window("bone", image, &roi), std::invalid_argument);
    // A flat image still gets a usable window.
    const auto flat = render::preset_window("auto", Grid<float>(lat, 3.0f), nullptr);
    EXPECT_LT(flat.low, 3.0);
    EXPECT_GT(flat.high, 3.0);
}

// A 20^3 image with a ramp along x, a ball of "segmentation" and a box ROI.
struct OverlayScene {
    Lattice lat{{20, 20, 20}};
    Grid<float> raw{lat}, unit{lat}, phi{lat};
    Grid<std::uint8_t> roi{lat};
    OverlayScene() {
        for (PointIndex i = 0; i < raw.size(); ++i) {
            const Vec3i p = lat.coord(i);
            raw[i] = static_cast<float>(10 * p.x);
            unit[i] = static_cast<float>(p.x) / 19.0f;
            phi[i] = static_cast<float>(std::hypot(p.x - 10.0, p.y - 10.0) - 5.0);
            roi[i] = p.x >= 3 && p.x <= 16 && p.y >= 2 && p.y <= 17;
        }
    }
};

std::array<int, 4> texel(const std::vector<std::uint8_t>& rgba, const render::SliceGeometry& g, Vec3i v) {
    const glm::dvec2 uv = g.to_uv(v.cast<double>());
    const auto c = static_cast<std::size_t>(uv.x), r = static_cast<std::size_t>(uv.y);
    const std::size_t k = 4 * (r * static_cast<std::size_t>(g.width) + c);
    return {rgba[k], rgba[k + 1], rgba[k + 2], rgba[k + 3]};
}

TEST(SliceOverlay, LabelOpacityRoiOutlineAndPreviewWhereTheDataTermIsNegative) {
    const OverlayScene s;
    const auto g = render::slice_geometry(s.lat, SliceAxis::kAxial);
    render::OverlayStyle style;
    style.roi = render::RoiStyle::kOff;
    style.label_opacity = 1.0f;
    auto t = render::overlay_texels(g, 10, style, render::phi_slice(s.phi, g, 10), &s.roi, nullptr, nullptr);
    EXPECT_EQ(texel(t, g, {10, 10, 10}), (std::array<int, 4>{230, 60, 50, 255}));  // inside: the label colour
    EXPECT_EQ(texel(t, g, {1, 1, 10})[3], 0);                                       // outside: transparent
    style.label_opacity = 0.0f;
    t = render::overlay_texels(g, 10, style, render::phi_slice(s.phi, g, 10), &s.roi, nullptr, nullptr);
    EXPECT_EQ(texel(t, g, {10, 10, 10})[3], 0);
    style.roi = render::RoiStyle::kOutline;
    t = render::overlay_texels(g, 10, style, render::phi_slice(s.phi, g, 10), &s.roi, nullptr, nullptr);
    EXPECT_EQ(texel(t, g, {3, 10, 10})[3], 255);   // the ROI's edge
    EXPECT_EQ(texel(t, g, {16, 2, 10})[3], 255);   // a corner
    EXPECT_EQ(texel(t, g, {8, 10, 10})[3], 0);     // inside, off the edge
    EXPECT_EQ(texel(t, g, {1, 10, 10})[3], 0);     // outside
    style.roi = render::RoiStyle::kTint;
    t = render::overlay_texels(g, 10, style, render::phi_slice(s.phi, g, 10), &s.roi, nullptr, nullptr);
    EXPECT_EQ(texel(t, g, {8, 10, 10}), (std::array<int, 4>{255, 210, 40, 51}));  // inside: 0.2 of the ROI colour
    EXPECT_EQ(texel(t, g, {1, 10, 10})[3], 0);
    // Preview: tinted exactly where threshold_term < 0 inside the ROI, more where D is lower.
    style = {};
    style.label_opacity = 0.0f;
    style.roi = render::RoiStyle::kOff;
    style.preview = true;
    const ThresholdParams params{0.5, 0.15, 4.0, 0.1};
    t = render::overlay_texels(g, 10, style, {}, &s.roi, &s.unit, &params);
    for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x) {
            const Vec3i v{x, y, 10};
            const double d = threshold_term(s.unit(v), params);
            const int alpha = texel(t, g, v)[3];
            if (s.roi(v) && d < 0.0) EXPECT_EQ(alpha, std::lround(255.0 * std::min(1.0, -d * 0.6))) << x << "," << y;
            else EXPECT_EQ(alpha, 0) << x << "," << y;
        }
}

// A coarse start's front previewed on the image's slices: the label fill is exactly the inside
// upsample_inside gives the fine start (every view, an oblique storage, odd dimensions), and the
// contour drawn from the preview's values lies where those values cross zero.
TEST(SliceOverlay, TheCoarseRunsPreviewIsWhereItsFrontWouldStartOnTheImagesGrid) {
    const Lattice fine({23, 18, 15}, {0.7, 0.7, 0.7}, {0, 0, 0}, Mat3d{0, 0, 1, -1, 0, 0, 0, 1, 0});
    const Lattice coarse = coarse_lattice(fine);
    Grid<float> phi(coarse);
    for (int z = 0; z < coarse.dims().z; ++z)
        for (int y = 0; y < coarse.dims().y; ++y)
            for (int x = 0; x < coarse.dims().x; ++x)
                phi({x, y, z}) = static_cast<float>(std::hypot(x - 5.3, 1.3 * (y - 4.1), z - 3.2) - 3.4);
    const Grid<std::uint8_t> inside = upsample_inside(phi, fine);
    render::OverlayStyle style;
    style.roi = render::RoiStyle::kOff;
    style.label_opacity = 1.0f;
    int filled = 0;
    for (const SliceAxis view : {SliceAxis::kAxial, SliceAxis::kCoronal, SliceAxis::kSagittal}) {
        const auto g = render::slice_geometry(fine, view);
        for (const int slice : {0, g.slices / 2, g.slices - 1}) {
            const std::vector<float> values = render::upsampled_phi_slice(phi, g, slice);
            const auto t = render::overlay_texels(g, slice, style, values, nullptr, nullptr, nullptr);
            for (int r = 0; r < g.height; ++r)
                for (int c = 0; c < g.width; ++c) {
                    const Vec3i v = g.voxel(c, r, slice);
                    const int alpha = t[4 * (static_cast<std::size_t>(r) * static_cast<std::size_t>(g.width) + static_cast<std::size_t>(c)) + 3];
                    EXPECT_EQ(alpha, inside(v) ? 255 : 0) << render::to_string(view) << " " << slice << " " << v;
                    filled += inside(v);
                }
            for (const glm::dvec2 p : render::zero_contour(values, g)) {  // on a texel edge between centres of both signs
                const auto c0 = static_cast<int>(std::floor(p.x - 0.5)), r0 = static_cast<int>(std::floor(p.y - 0.5));
                bool in = false, out = false;
                for (int dr = 0; dr <= 1; ++dr)
                    for (int dc = 0; dc <= 1; ++dc) {
                        const int c = std::clamp(c0 + dc, 0, g.width - 1), r = std::clamp(r0 + dr, 0, g.height - 1);
                        (inside(g.voxel(c, r, slice)) ? in : out) = true;
                    }
                EXPECT_TRUE(in && out) << render::to_string(view) << " " << slice << " (" << p.x << ", " << p.y << ")";
            }
        }
    }
    EXPECT_GT(filled, 200);
    const auto g = render::slice_geometry(fine, SliceAxis::kAxial);
    EXPECT_THROW(render::overlay_texels(g, 0, style, std::vector<float>(3, -1.0f), nullptr, nullptr, nullptr), std::invalid_argument);
    EXPECT_THROW(render::zero_contour(std::vector<float>(3, -1.0f), g), std::invalid_argument);
}

TEST(EdgeLetters, RadiologicalLettersFollowTheDirectionCosines) {
    const auto letters = [](const Lattice& l, SliceAxis v) {
        const render::EdgeLetters e = render::edge_letters(l, render::slice_geometry(l, v));
        return std::string{e.left, e.right, e.top, e.bottom};
    };
    const Lattice lps({30, 40, 20});
    EXPECT_EQ(letters(lps, SliceAxis::kAxial), "RLAP");
    EXPECT_EQ(letters(lps, SliceAxis::kCoronal), "RLSI");
    EXPECT_EQ(letters(lps, SliceAxis::kSagittal), "APSI");
    // Flipped and permuted storage: the panes re-orient, the letters say the same anatomy.
    const Mat3d flipped{-1, 0, 0, 0, -1, 0, 0, 0, 1};          // RAS-like storage (as MINC)
    const Mat3d permuted{0, 0, 1, -1, 0, 0, 0, 1, 0};          // i -> -y, j -> +z, k -> +x
    for (const Mat3d& d : {flipped, permuted}) {
        const Lattice l({30, 40, 20}, {1, 1, 1}, {0, 0, 0}, d);
        EXPECT_EQ(letters(l, SliceAxis::kAxial), "RLAP");
        EXPECT_EQ(letters(l, SliceAxis::kSagittal), "APSI");
    }
    // The letters come from the geometry actually shown: flip the screen's axes and they swap.
    auto g = render::slice_geometry(lps, SliceAxis::kAxial);
    g.u_flip = !g.u_flip;
    g.v_flip = !g.v_flip;
    const render::EdgeLetters e = render::edge_letters(lps, g);
    EXPECT_EQ((std::string{e.left, e.right, e.top, e.bottom}), "LRPA");
    g.u_axis = 2;  // k (superior) along the screen's right
    EXPECT_EQ(render::edge_letters(lps, g).right, 'I');
}

TEST(CursorCoordinates, OneBasedVoxelsAndMillimetresRoundTrip) {
    const Mat3d permuted{0, 0, 1, -1, 0, 0, 0, 1, 0};
    const Lattice l({30, 40, 20}, {1.5, 0.8, 2.2}, {-31.0, 17.5, 40.25}, permuted);
    const Vec3i v{12, 3, 19};
    EXPECT_EQ(render::one_based(v), (Vec3i{13, 4, 20}));
    const Vec3d lps = render::lps_of(l, v), ras = render::ras_of(l, v);
    EXPECT_DOUBLE_EQ(ras.x, -lps.x);
    EXPECT_DOUBLE_EQ(ras.y, -lps.y);
    EXPECT_DOUBLE_EQ(ras.z, lps.z);
    // k runs along +x (LPS) at 2.2 mm: voxel k = 19 lies 19 * 2.2 mm from the origin along x.
    EXPECT_NEAR(lps.x, -31.0 + 19 * 2.2, 1e-9);
    EXPECT_EQ(render::voxel_from(l, {13, 4, 20}, render::CursorUnits::kVoxel1), v);
    EXPECT_EQ(render::voxel_from(l, lps + Vec3d{0.3, -0.2, 0.1}, render::CursorUnits::kLps), v);
    EXPECT_EQ(render::voxel_from(l, ras, render::CursorUnits::kRas), v);
    EXPECT_FALSE(render::voxel_from(l, {0, 4, 20}, render::CursorUnits::kVoxel1));  // 1-based: 0 is outside
    EXPECT_FALSE(render::voxel_from(l, {1e300, 0, 0}, render::CursorUnits::kLps));
    EXPECT_EQ(render::parse_triple(" 12, 40 7 "), (Vec3d{12, 40, 7}));
    EXPECT_EQ(render::parse_triple("-3.5,12,4e1"), (Vec3d{-3.5, 12, 40}));
    EXPECT_FALSE(render::parse_triple("12 40"));
    EXPECT_FALSE(render::parse_triple("12 40 7 8"));
    EXPECT_FALSE(render::parse_triple("a b c"));
}

// nibabel (Debian's python) reads a NIfTI we wrote with permuted, flipped axes: its affine gives
// the RAS millimetres of voxels and aff2axcodes the letters each lattice axis points to.
TEST(CursorCoordinates, MillimetresAndLettersAgreeWithNibabel) {
    if (std::system("/usr/bin/python3 -c 'import nibabel' >/dev/null 2>&1") != 0) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel";
    const auto dir = testing::scratch_dir("slice_nib");
    const Mat3d d{0, 0, -1, 1, 0, 0, 0, -1, 0};  // i -> +y (P), j -> -z (I), k -> -x (R)
    const Lattice l({7, 9, 5}, {1.5, 0.8, 2.2}, {12.0, -20.5, 33.0}, d);
    write_image(Grid<float>(l, 1.0f), (dir / "img.nii.gz").string());
    const std::vector<Vec3i> voxels{{0, 0, 0}, {6, 8, 4}, {3, 1, 2}};
    const std::string cmd = "/usr/bin/python3 -c \"import nibabel as nib, numpy as np; i = nib.load('" + (dir / "img.nii.gz").string() +
                            "'); print(''.join(nib.aff2axcodes(i.affine))); [print(*(i.affine @ [x, y, z, 1])[:3]) for x, y, z in "
                            "[(0, 0, 0), (6, 8, 4), (3, 1, 2)]]\" > " + (dir / "out.txt").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream in(dir / "out.txt");
    std::string codes;
    in >> codes;
    ASSERT_EQ(codes.size(), 3u);
    for (int axis = 0; axis < 3; ++axis) {
        const auto a = static_cast<std::size_t>(axis);
        EXPECT_EQ(render::direction_letter({d[a], d[3 + a], d[6 + a]}), codes[a]) << "axis " << axis;
    }
    for (const Vec3i& v : voxels) {
        Vec3d ras{};
        in >> ras.x >> ras.y >> ras.z;
        const Vec3d ours = render::ras_of(l, v);
        EXPECT_NEAR(ours.x, ras.x, 1e-4);
        EXPECT_NEAR(ours.y, ras.y, 1e-4);
        EXPECT_NEAR(ours.z, ras.z, 1e-4);
        EXPECT_EQ(render::voxel_from(l, ras, render::CursorUnits::kRas), v);
    }
    std::filesystem::remove_all(dir);
}

// An image stored in other orientations (nibabel re-orients the phantom to PIR and to RAS axes, an
// independent tool): read back, every pane shows the same picture as of the LPS original, with the
// same letters.
TEST(EdgeLetters, ReorientedCopiesShowTheSameAnatomy) {
    if (std::system("/usr/bin/python3 -c 'import nibabel' >/dev/null 2>&1") != 0) GTEST_SKIP() << "needs /usr/bin/python3 with nibabel";
    const auto dir = testing::scratch_dir("slice_reorient");
    const Grid<float>& original = testing::phantom64().image;
    write_image(original, (dir / "lps.nii.gz").string());
    const std::string cmd = "cd " + dir.string() +
                            " && /usr/bin/python3 -c \"import nibabel as nib; from nibabel.orientations import *; i = nib.load('lps.nii.gz'); "
                            "[nib.save(i.as_reoriented(ornt_transform(io_orientation(i.affine), axcodes2ornt(c))), ''.join(c) + '.nii.gz') "
                            "for c in [('P', 'I', 'R'), ('R', 'A', 'S')]]\"";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    const Vec3d world = original.lattice().to_world({32, 30, 21});
    for (const char* name : {"PIR", "RAS"}) {
        const Grid<float> copy = read_image((dir / (std::string(name) + ".nii.gz")).string());
        ASSERT_FALSE(copy.lattice().same_geometry(original.lattice())) << name;
        for (const SliceAxis view : {SliceAxis::kAxial, SliceAxis::kCoronal, SliceAxis::kSagittal}) {
            const auto g0 = render::slice_geometry(original.lattice(), view), g1 = render::slice_geometry(copy.lattice(), view);
            const render::EdgeLetters a = render::edge_letters(original.lattice(), g0), b = render::edge_letters(copy.lattice(), g1);
            EXPECT_EQ((std::string{a.left, a.right, a.top, a.bottom}), (std::string{b.left, b.right, b.top, b.bottom})) << name;
            const render::DisplayWindow w = render::preset_window("minmax", original, nullptr);
            const int s0 = g0.slice_of(original.lattice().to_index(world)), s1 = g1.slice_of(copy.lattice().to_index(world));
            const auto t0 = render::window_texels(original, g0, s0, w);
            EXPECT_GT(std::set<std::uint8_t>(t0.begin(), t0.end()).size(), 10u);  // a picture, not a flat slice
            EXPECT_EQ(t0, render::window_texels(copy, g1, s1, w)) << name << " " << to_string(view);
        }
    }
    std::filesystem::remove_all(dir);
}

// The pane as drawn: at zoom 2 a voxel covers 15 pixels, so its centre pixel shows exactly its grey
// through the window, or the label colour over it at opacity 1.
TEST(SliceRender, WindowGreyAndLabelOpacityAtAKnownVoxel) {
    testing::gl_context();
    const OverlayScene s;
    const auto g = render::slice_geometry(s.lat, SliceAxis::kAxial);
    render::SliceViewport vp = render::SliceViewport::fit(g, 160, 160);
    vp = render::zoom_about(vp, {80.0, 80.0}, 2.0);
    const render::DisplayWindow w{25.0, 175.0};
    render::SliceRenderer renderer;
    renderer.set_texels(g.width, g.height, render::window_texels(s.raw, g, 10, w));
    render::Framebuffer fb(160, 160);
    const auto pixel_at = [&](Vec3i v, float opacity) {
        render::OverlayStyle style;
        style.roi = render::RoiStyle::kOff;
        style.label_opacity = opacity;
        renderer.set_overlay(g.width, g.height, render::overlay_texels(g, 10, style, render::phi_slice(s.phi, g, 10), nullptr, nullptr, nullptr));
        render::SliceOverlay overlay;
        overlay.layer = true;
        renderer.render(fb, vp, overlay, render::SliceStyle{});
        const render::Image img = fb.read_color();
        const glm::dvec2 p = vp.to_pixel(g.to_uv(v.cast<double>()));
        const std::size_t k = 4 * (static_cast<std::size_t>(p.y) * 160 + static_cast<std::size_t>(p.x));
        return std::array<int, 3>{img.rgba[k], img.rgba[k + 1], img.rgba[k + 2]};
    };
    const Vec3i inside{9, 11, 10};  // raw 90, inside the disc
    const int grey = std::lround(255.0 * (90.0 - 25.0) / 150.0);
    EXPECT_EQ(pixel_at(inside, 0.0f), (std::array<int, 3>{grey, grey, grey}));
    EXPECT_EQ(pixel_at(inside, 1.0f), (std::array<int, 3>{230, 60, 50}));
    const auto half = pixel_at(inside, 0.5f);
    EXPECT_NEAR(half[0], 0.5 * (230 + grey), 1.5);
    EXPECT_NEAR(half[1], 0.5 * (60 + grey), 1.5);
    const Vec3i outside{14, 5, 10};  // raw 140: outside the disc, untouched by the overlay
    const int g140 = std::lround(255.0 * (140.0 - 25.0) / 150.0);
    EXPECT_EQ(pixel_at(outside, 1.0f), (std::array<int, 3>{g140, g140, g140}));
}

}  // namespace
}  // namespace liveset
