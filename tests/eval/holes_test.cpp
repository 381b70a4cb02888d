// The truth-free hole finder: against shells drilled by hand (brute-force expected voxels), the
// enclosed-CSF rule, and the truth's perforations on the segmented phantom (recall).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "liveset/eval/holes.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/window.hpp"
#include "mask_shapes.hpp"

namespace liveset {
namespace {

using test::Mask;

constexpr float kCsf = 50, kGm = 100, kWm = 130;
const Vec3d kCentre{24, 24, 24};

// A 48^3 image: WM ball r <= 12, GM shell 12 < r <= 16, CSF outside; the mask is the GM shell
// minus the voxels a drill (cylinder of radius `drill` along +x from the centre) removes.
struct Shell {
    Grid<float> image{Lattice({48, 48, 48}), kCsf};
    Mask mask{Lattice({48, 48, 48}), 0};
    Mask drilled{Lattice({48, 48, 48}), 0};  // shell voxels the drill removed
};

Shell make_shell(double drill) {
    Shell s;
    const Vec3i d = s.image.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const Vec3d p{double(x), double(y), double(z)};
                const double r = norm(p - kCentre);
                const bool in_drill = p.x > kCentre.x && std::hypot(p.y - kCentre.y, p.z - kCentre.z) <= drill;
                if (r <= 12) s.image({x, y, z}) = kWm;
                else if (r <= 16) {
                    s.image({x, y, z}) = kGm;
                    (in_drill ? s.drilled : s.mask)({x, y, z}) = 1;
                }
            }
    return s;
}

HoleFinderOptions band() {
    HoleFinderOptions o;
    o.sheet_lower = (kCsf + kGm) / 2;
    o.sheet_upper = (kGm + kWm) / 2;
    return o;
}

std::size_t count(const Mask& m) {
    std::size_t n = 0;
    for (std::uint8_t v : m.values()) n += v != 0;
    return n;
}

TEST(Holes, ADrilledShellHasExactlyItsDrillHole) {
    const Shell s = make_shell(2.5);
    const auto holes = find_holes(s.mask, s.image, nullptr, band());
    ASSERT_EQ(holes.size(), 1u);
    EXPECT_EQ(holes[0].voxels, count(s.drilled));  // brute force: the drilled shell voxels
    EXPECT_TRUE(s.drilled(holes[0].site));          // the site lies in the hole
    EXPECT_GT(holes[0].site.x, 24 + 12);            // on the drilled side
    const Mask v = hole_voxels(s.mask, s.image, nullptr, band());
    for (PointIndex i = 0; i < v.size(); ++i) ASSERT_EQ(v[i], s.drilled[i]);
}

TEST(Holes, AClosedShellHasNone) {
    const Shell s = make_shell(0.0 - 1.0);  // no drill
    EXPECT_TRUE(find_holes(s.mask, s.image, nullptr, band()).empty());
}

TEST(Holes, TheSameHoleWithTheTruthsPerforation) {
    const Shell s = make_shell(3.0);
    Mask truth = s.mask, inner(s.mask.lattice(), 0);
    for (PointIndex i = 0; i < truth.size(); ++i) {
        truth[i] = s.image[i] == kGm;
        inner[i] = s.image[i] == kWm;
    }
    const auto p = find_perforations(s.mask, truth, inner);
    const auto h = find_holes(s.mask, s.image, nullptr, band());
    ASSERT_EQ(p.size(), 1u);
    ASSERT_EQ(h.size(), 1u);
    EXPECT_EQ(p[0].voxels, h[0].voxels);
}

// A gap between the inner tissue and CSF that the inner tissue encloses (a ventricle) is no hole:
// that CSF is not the outside.
TEST(Holes, EnclosedCsfIsNotTheOutside) {
    Shell s = make_shell(-1.0);
    Mask ventricle(s.mask.lattice(), 0), gap(s.mask.lattice(), 0);
    test::paint_ball(ventricle, kCentre, 4.0);
    test::paint(gap, [](Vec3d p) { const double r = norm(p - kCentre); return r > 4.0 && r <= 6.0 && p.x > 24; });
    for (PointIndex i = 0; i < ventricle.size(); ++i) {
        if (ventricle[i]) s.image[i] = kCsf;
        if (gap[i]) s.image[i] = kGm;
    }
    EXPECT_TRUE(find_holes(s.mask, s.image, nullptr, band()).empty());
    // Open the shell to the outside (drill it): now the drill's hole is found, the ventricle's gap still is not.
    const Shell drilled = make_shell(2.5);
    Mask m = drilled.mask;
    const auto holes = find_holes(m, s.image, nullptr, band());
    ASSERT_EQ(holes.size(), 1u);
    EXPECT_EQ(holes[0].voxels, count(drilled.drilled));
}

// Outside the ROI counts as the outside: a gap touching the ROI's border and the inner tissue.
TEST(Holes, OutsideTheRoiIsTheOutside) {
    const Shell s = make_shell(2.5);
    Mask roi(s.mask.lattice(), 0);
    test::paint_ball(roi, kCentre, 17.0);
    EXPECT_EQ(find_holes(s.mask, s.image, &roi, band()).size(), 1u);
}

TEST(Holes, VoxelsNearASiteByBruteForce) {
    const Shell s = make_shell(2.5);
    const Mask v = hole_voxels(s.mask, s.image, nullptr, band());
    const Vec3d site{38.3, 24.2, 23.6};
    for (double r : {0.5, 2.0, 3.7, 6.0}) {
        std::size_t n = 0;
        for (PointIndex i = 0; i < v.size(); ++i) n += v[i] && norm(v.lattice().coord(i).cast<double>() - site) <= r;
        EXPECT_EQ(hole_voxels_near(v, site, r), n) << r;
    }
}

TEST(Holes, BadInputThrows) {
    const Shell s = make_shell(2.5);
    HoleFinderOptions bad = band();
    bad.sheet_upper = bad.sheet_lower;
    EXPECT_THROW(find_holes(s.mask, s.image, nullptr, bad), std::invalid_argument);
    const Mask small(Lattice({8, 8, 8}), 0);
    EXPECT_THROW(find_holes(small, s.image, nullptr, band()), std::invalid_argument);
    EXPECT_THROW(find_holes(s.mask, s.image, &small, band()), std::invalid_argument);
}

// The phantom segmented with the seeds' window: every truth perforation of >= 50 voxels (a region
// of missed grey matter joining white matter to the outside) holds voxels of the finder's holes,
// found from the tissue model's band alone (recall 1), and most of the finder's hole voxels are
// missed grey matter (precision).
TEST(Holes, FindsThePhantomsPerforationsWithoutTruth) {
    const Phantom ph = make_phantom();
    SegmentRequest req;
    for (const Vec3i& s : ph.seeds) req.seeds.push_back({s.cast<double>(), 2.0});
    req.window.estimate = WindowSource::kSeeds;
    const SegmentOutcome o = segment_image(ph.image, req);
    Mask white(ph.labels.lattice(), 0), missed(ph.labels.lattice(), 0);
    for (PointIndex i = 0; i < white.size(); ++i) {
        white[i] = ph.labels[i] == kWhiteMatter;
        missed[i] = ph.truth[i] && !o.mask[i];
    }
    const auto truth = find_perforations(o.mask, ph.truth, white);
    const ComponentLabels region = label_components(missed, 6, nullptr);
    std::vector<std::string> warnings;
    const auto w = sheet_window(ph.image, o.mask, nullptr, TissueModelOptions{}, warnings);
    ASSERT_TRUE(w.has_value());
    HoleFinderOptions fo;
    fo.sheet_lower = w->lower;
    fo.sheet_upper = w->upper;
    const Mask found = hole_voxels(o.mask, ph.image, nullptr, fo);
    std::size_t large = 0, met = 0, found_voxels = 0, found_missed = 0;
    for (const Perforation& p : truth) {
        if (p.voxels < 50) continue;
        ++large;
        const std::uint32_t k = region[o.mask.lattice().index(p.nearest)];
        bool hit = false;
        for (PointIndex i = 0; i < found.size() && !hit; ++i) hit = found[i] && region[i] == k;
        met += hit;
    }
    for (PointIndex i = 0; i < found.size(); ++i) {
        found_voxels += found[i] != 0;
        found_missed += found[i] && missed[i];
    }
    EXPECT_EQ(large, 2u);  // the phantom's two weak spots
    EXPECT_EQ(met, large);
    // Precision by voxel (measured 380 of 584 = 0.65; the rest partial-volume voxels on the
    // white matter / CSF border that read as grey matter).
    EXPECT_GE(static_cast<double>(found_missed), 0.6 * static_cast<double>(found_voxels));
}

}  // namespace
}  // namespace liveset
