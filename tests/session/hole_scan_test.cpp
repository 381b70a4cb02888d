// The hole finder as the viewer runs it (session/hole_scan.hpp): on the 64^3 phantom whose
// grey-matter truth has a hole drilled by hand, the tissue model's band finds the drill (its site
// on the drilled voxels, all of them in the band in the candidate), the intact truth has no candidate there;
// the verdict after the drilled voxels are put back is "closed" (exactly hole_verdict's counts by
// brute force) and "no hole" at a site far from it; a session's band comes from its model region;
// bad options throw.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "hole_phantom.hpp"
#include "liveset/session/hole_scan.hpp"
#include "liveset/session/session.hpp"

namespace liveset {
namespace {

using testing::DrilledPhantom;
using testing::drilled_phantom;

// Hole voxels within kHoleVerdictRadius of `site`, by brute force over the whole grid.
std::size_t near_by_brute_force(const Grid<std::uint8_t>& holes, Vec3d site) {
    std::size_t n = 0;
    for (PointIndex i = 0; i < holes.size(); ++i) {
        const Vec3d d = holes.lattice().coord(i).cast<double>() - site;
        n += holes[i] && dot(d, d) <= kHoleVerdictRadius * kHoleVerdictRadius;
    }
    return n;
}

TEST(HoleScan, FindsADrilledHoleWithTheTissueModelsBand) {
    const DrilledPhantom& d = drilled_phantom();
    const HoleScan s = scan_holes(d.mask, d.phantom.image, nullptr, HoleScanOptions{});
    EXPECT_EQ(s.band_from, "tissue model");
    ASSERT_FALSE(s.holes.empty());
    // The drill is the largest candidate; its site is a drilled voxel; every drilled voxel is in it.
    const HoleCandidate& h = s.holes.front();
    EXPECT_TRUE(d.drilled(h.site)) << h.site.x << "," << h.site.y << "," << h.site.z;
    // Every drilled voxel whose intensity lies in the sheet's band is a hole voxel (the few noisy
    // ones outside the band are not gaps by the rule).
    const Grid<std::uint8_t> holes = hole_voxels(s.mask, d.phantom.image, nullptr, s.finder);
    std::size_t in_band = 0, missed = 0;
    for (PointIndex i = 0; i < holes.size(); ++i) {
        const double v = d.phantom.image[i];
        const bool band = v >= s.finder.sheet_lower && v < s.finder.sheet_upper;
        in_band += d.drilled[i] && band;
        missed += d.drilled[i] && band && !holes[i];
    }
    EXPECT_EQ(missed, 0u);
    EXPECT_GE(in_band, d.drilled_voxels * 9 / 10);
    EXPECT_GE(h.voxels, in_band);
    // The intact shell: no candidate within the verdict radius of the drill.
    const HoleScan intact = scan_holes(d.phantom.truth, d.phantom.image, nullptr, HoleScanOptions{});
    for (const HoleCandidate& c : intact.holes) EXPECT_GT(norm((c.site - h.site).cast<double>()), kHoleVerdictRadius);
}

TEST(HoleScan, VerdictsAfterTheDrillIsFilled) {
    const DrilledPhantom& d = drilled_phantom();
    HoleScanOptions o;
    const HoleScan before = scan_holes(d.mask, d.phantom.image, nullptr, o);
    ASSERT_FALSE(before.holes.empty());
    o.sheet_lower = before.finder.sheet_lower;  // the same band, given
    o.sheet_upper = before.finder.sheet_upper;
    const HoleScan after = scan_holes(d.phantom.truth, d.phantom.image, nullptr, o);
    EXPECT_EQ(after.band_from, "given");
    const Vec3d site = before.holes.front().site.cast<double>();
    const Vec3d far{4.0, 4.0, 4.0};  // background corner: no sheet, no hole
    const std::vector<Vec3d> sites{site, far};
    const std::vector<HoleVerdict> v = hole_verdicts(sites, before, after, d.phantom.image, nullptr);
    ASSERT_EQ(v.size(), 2u);
    const Grid<std::uint8_t> hb = hole_voxels(before.mask, d.phantom.image, nullptr, before.finder);
    const Grid<std::uint8_t> ha = hole_voxels(after.mask, d.phantom.image, nullptr, before.finder);
    EXPECT_EQ(v[0].before, near_by_brute_force(hb, site));
    EXPECT_EQ(v[0].after, near_by_brute_force(ha, site));
    EXPECT_GT(v[0].before, 0u);
    EXPECT_EQ(v[0].after, 0u);
    EXPECT_TRUE(v[0].closed);
    EXPECT_GT(v[0].genus_before, v[0].genus_after);  // the drill is a tunnel through the shell's box
    EXPECT_EQ(v[1].before, 0u);
    EXPECT_EQ(v[1].after, 0u);
    EXPECT_TRUE(hole_verdicts({}, before, after, d.phantom.image, nullptr).empty());
}

// A session's hole finder reads the band from where the session's tissue model was fitted (its
// model region, e.g. the brain mask found before N4), not from a brain looked for again: the band
// is sheet_window's with that region as the ROI (the mask lies inside it, so the same voxels vote),
// and the model behind it is the session's own.
TEST(HoleScan, TheBandComesFromTheSessionsModelRegion) {
    const DrilledPhantom& d = drilled_phantom();
    // CSF, GM and half of the WM: not what the automatic mask finds (the grey-matter sheet is all in it).
    Grid<std::uint8_t> tissue(d.phantom.labels.lattice(), 0);
    const int half = tissue.dims().x / 2;
    for (PointIndex i = 0; i < tissue.size(); ++i) {
        const std::uint8_t l = d.phantom.labels[i];
        tissue[i] = l != kBackground && (l != kWhiteMatter || tissue.lattice().coord(i).x < half);
    }
    SessionOptions so;
    so.model_region = tissue;
    so.model_region_is_brain = true;
    const Session session(d.phantom.image, so);
    const HoleScan got = scan_holes(d.mask, d.phantom.image, nullptr, HoleScanOptions{}, session.sheet_fit());

    std::vector<std::string> warnings;
    TissueModel in_region, looked_for;
    SheetFit as_roi;
    as_roi.region_is_brain = true;
    const std::optional<ModelWindow> want = sheet_window(d.phantom.image, d.mask, &tissue, TissueModelOptions{}, warnings, &in_region, as_roi);
    ASSERT_TRUE(want.has_value());
    EXPECT_EQ(got.finder.sheet_lower, want->lower);
    EXPECT_EQ(got.finder.sheet_upper, want->upper);
    ASSERT_TRUE(session.tissue_model().has_value());
    ASSERT_EQ(session.tissue_model()->classes.size(), in_region.classes.size());
    for (std::size_t k = 0; k < in_region.classes.size(); ++k) {
        EXPECT_EQ(session.tissue_model()->classes[k].mean, in_region.classes[k].mean);
        EXPECT_EQ(session.tissue_model()->classes[k].weight, in_region.classes[k].weight);
    }
    // Without the session's region, the model is fitted where model_region() looks: elsewhere.
    ASSERT_TRUE(sheet_window(d.phantom.image, d.mask, nullptr, TissueModelOptions{}, warnings, &looked_for).has_value());
    ASSERT_EQ(looked_for.classes.size(), in_region.classes.size());
    double moved = 0;
    for (std::size_t k = 0; k < in_region.classes.size(); ++k) moved += std::abs(looked_for.classes[k].weight - in_region.classes[k].weight);
    EXPECT_GT(moved, 0.05);
    std::vector<std::string> ignored;
    const std::optional<ModelWindow> elsewhere = sheet_window(d.phantom.image, d.mask, nullptr, TissueModelOptions{}, ignored);
    ASSERT_TRUE(elsewhere.has_value());
    EXPECT_NE(elsewhere->lower, got.finder.sheet_lower);
    // A model region of another size is an error, not a crash.
    SheetFit small;
    const Grid<std::uint8_t> other(Lattice({8, 8, 8}), 1);
    small.region = &other;
    EXPECT_THROW(scan_holes(d.mask, d.phantom.image, nullptr, HoleScanOptions{}, small), std::invalid_argument);
}

TEST(HoleScan, BadOptionsThrow) {
    const DrilledPhantom& d = drilled_phantom();
    HoleScanOptions o;
    o.sheet_lower = 10.0;  // one end only
    EXPECT_THROW(scan_holes(d.mask, d.phantom.image, nullptr, o), std::invalid_argument);
    o.sheet_upper = 5.0;  // upside down
    EXPECT_THROW(scan_holes(d.mask, d.phantom.image, nullptr, o), std::invalid_argument);
    HoleScanOptions z;
    z.min_voxels = 0;
    EXPECT_THROW(z.validate(), std::invalid_argument);
    Grid<std::uint8_t> small(Lattice({8, 8, 8}), 1);
    EXPECT_THROW(scan_holes(small, d.phantom.image, nullptr, HoleScanOptions{}), std::invalid_argument);
    // A flat image: no tissue model, no band given.
    const Grid<float> flat(d.phantom.image.lattice(), 100.0f);
    EXPECT_THROW(scan_holes(d.mask, flat, nullptr, HoleScanOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
