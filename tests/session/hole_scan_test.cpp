// The hole finder as the viewer runs it (session/hole_scan.hpp): on the 64^3 phantom whose
// grey-matter truth has a hole drilled by hand, the tissue model's band finds the drill (its site
// on the drilled voxels, all of them in the band in the candidate), the intact truth has no candidate there;
// the verdict after the drilled voxels are put back is "closed" (exactly hole_verdict's counts by
// brute force) and "no hole" at a site far from it; bad options throw.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "hole_phantom.hpp"
#include "liveset/session/hole_scan.hpp"

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
