// The sheet repair rule (EditDecision::kSheet) and the repair schedule on a drilled shell whose
// truth is known analytically: the hole closes, only sheet voxels are added, nothing contracts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "liveset/eval/holes.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/swarm/repair_schedule.hpp"

namespace liveset {
namespace {

// The white-matter core is larger than the topology guard's pocket limit (32 768 voxels): sealing
// a smaller core off counts as making a spurious cavity, and the guard refuses the last voxel.
constexpr int kN = 64;
const Vec3d kCentre{32, 32, 32};
constexpr double kCore = 21, kOuter = 25;
constexpr float kCsf = 0.2f, kGm = 0.5f, kWm = 0.8f;  // normalised intensities
constexpr double kLower = 0.35, kUpper = 0.65;        // midpoints: the sheet's band

// WM ball r <= kCore, GM shell kCore < r <= kOuter, CSF outside; the mask is the shell minus a drill of
// radius `drill` along +x.
struct Shell {
    Grid<float> image{Lattice({kN, kN, kN}), kCsf};
    Grid<std::uint8_t> mask{Lattice({kN, kN, kN}), 0};
};

Shell drilled_shell(double drill) {
    Shell s;
    for (int z = 0; z < kN; ++z)
        for (int y = 0; y < kN; ++y)
            for (int x = 0; x < kN; ++x) {
                const Vec3d p{double(x), double(y), double(z)};
                const double r = norm(p - kCentre);
                if (r <= kCore) s.image({x, y, z}) = kWm;
                else if (r <= kOuter) {
                    s.image({x, y, z}) = kGm;
                    s.mask({x, y, z}) = !(p.x > kCentre.x && std::hypot(p.y - kCentre.y, p.z - kCentre.z) <= drill);
                }
            }
    return s;
}

HoleFinderOptions finder() {
    HoleFinderOptions o;
    o.sheet_lower = kLower;
    o.sheet_upper = kUpper;
    return o;
}

RepairOptions sheet_options() {
    RepairOptions ro;
    ro.swarm.agents = 200;
    ro.swarm.decision = EditDecision::kSheet;
    ro.swarm.sheet_lower = kLower;
    ro.swarm.sheet_upper = kUpper;
    ro.swarm.edit_radius = 2.0;
    ro.swarm.act_probability = 0.3;
    return ro;
}

TEST(SheetRepair, ClosesADrilledHoleAddingOnlySheetVoxels) {
    const Shell s = drilled_shell(3.0);
    SparseField field(s.mask.lattice(), 2);
    field.init_from_mask(s.mask);
    ASSERT_EQ(find_holes(s.mask, s.image, nullptr, finder()).size(), 1u);
    const HoleSiteFinder find = [&](const SparseField& f) {
        std::vector<HoleSite> out;
        for (const HoleCandidate& h : find_holes(inside_mask(f.phi()), s.image, nullptr, finder()))
            out.push_back({h.site.cast<double>(), h.voxels});
        return out;
    };
    RepairScheduleOptions so;
    so.rounds = 5;
    so.round_steps = 200;
    const RepairScheduleResult r = run_repair_schedule(field, s.image, nullptr, sheet_options(), so, find);
    EXPECT_EQ(r.holes_left, 0u);  // the finder's verdict
    const Grid<std::uint8_t> after = inside_mask(field.phi());
    EXPECT_EQ(mask_topology(after).genus, 0);  // the tunnel closed: a closed shell
    for (PointIndex i = 0; i < after.size(); ++i) {
        if (s.mask[i]) {
            ASSERT_TRUE(after[i]) << "the sheet rule never contracts";
        }
        if (after[i] && !s.mask[i]) {
            ASSERT_EQ(s.image[i], kGm) << "added a voxel that is not the sheet's tissue";
        }
    }
}

TEST(SheetRepair, NeverGrowsIntoTheNeighbouringTissues) {
    // An intact shell: every outside voxel next to it is WM or CSF, so nothing may be added
    // wherever the swarm is aimed.
    const Shell s = drilled_shell(-1.0);
    SparseField field(s.mask.lattice(), 2);
    field.init_from_mask(s.mask);
    RepairOptions ro = sheet_options();
    ro.steps = 300;
    const RepairTarget t{{kCentre.x + 23, kCentre.y, kCentre.z}, 0};
    run_repair(field, s.image, nullptr, {&t, 1}, ro);
    const Grid<std::uint8_t> after = inside_mask(field.phi());
    for (PointIndex i = 0; i < after.size(); ++i) ASSERT_EQ(after[i], s.mask[i]);
}

TEST(SheetRepair, LocalBandFollowsTheSheetsOwnIntensity) {
    Shell s = drilled_shell(-1.0);
    for (float& v : s.image.values())
        if (v == kGm) v = kGm + 0.04f;  // a local bias: the sheet reads 0.54
    Grid<float> phi(s.mask.lattice(), 1.0f);
    for (PointIndex i = 0; i < phi.size(); ++i)
        if (s.mask[i]) phi[i] = -1.0f;
    const auto [lo, hi] = local_sheet_band(s.image, phi, {kCentre.x + 23, kCentre.y, kCentre.z}, 6.0, kLower, kUpper, kGm);
    EXPECT_NEAR(lo, kLower + 0.04, 1e-6);
    EXPECT_NEAR(hi, kUpper + 0.04, 1e-6);
    // Too few sheet voxels near the site: the model's band unchanged.
    const auto [lo2, hi2] = local_sheet_band(s.image, phi, {2, 2, 2}, 3.0, kLower, kUpper, kGm);
    EXPECT_DOUBLE_EQ(lo2, kLower);
    EXPECT_DOUBLE_EQ(hi2, kUpper);
}

// A repair that grew into the white matter can wall a pocket of it off; a missed-GM tube from the
// outside into that pocket touches white matter and the outside like a perforation, and filling it
// raises the Euler characteristic like one (it seals the pocket), yet it is no hole of the shell.
// The truth finder lists the real perforation only; with it filled the mask has the truth's
// topology (checked by brute force), the tube still open.
TEST(SheetRepair, ATubeIntoAWalledOffPocketIsNoHole) {
    Shell s = drilled_shell(1.5);  // the real perforation, along +x
    Grid<std::uint8_t> truth(s.mask.lattice(), 0), inner(s.mask.lattice(), 0), tube(s.mask.lattice(), 0);
    for (int z = 0; z < kN; ++z)
        for (int y = 0; y < kN; ++y)
            for (int x = 0; x < kN; ++x) {
                const double r = norm(Vec3d{double(x), double(y), double(z)} - kCentre);
                truth({x, y, z}) = r > kCore && r <= kOuter;
                inner({x, y, z}) = r <= kCore;
            }
    // The pocket: white matter x 12..14, y, z 31..33, and (11,32,32) (r = 21, white matter) between it and
    // the grey matter; walled in by the mask over the box x 11..15, y, z 30..34; the tube: the grey
    // matter on the line y = z = 32 from x = 10 out to the CSF.
    const auto in_pocket = [](Vec3i q) {
        return (q.x >= 12 && q.x <= 14 && std::abs(q.y - 32) <= 1 && std::abs(q.z - 32) <= 1) || q == Vec3i{11, 32, 32};
    };
    for (int z = 30; z <= 34; ++z)
        for (int y = 30; y <= 34; ++y)
            for (int x = 11; x <= 15; ++x) s.mask({x, y, z}) = !in_pocket({x, y, z});
    for (int x = 0; x < 11; ++x)
        if (truth({x, 32, 32})) {
            tube({x, 32, 32}) = 1;
            s.mask({x, 32, 32}) = 0;
        }
    const auto with = [](Grid<std::uint8_t> m, const Grid<std::uint8_t>& add) {
        for (PointIndex i = 0; i < m.size(); ++i) m[i] = m[i] || add[i];
        return m;
    };
    Grid<std::uint8_t> drill(s.mask.lattice(), 0);
    for (PointIndex i = 0; i < drill.size(); ++i) drill[i] = truth[i] && !s.mask[i] && !tube[i];
    // The premise, by brute force: both look like perforations and filling either raises χ by one.
    ASSERT_EQ(find_perforations(s.mask, truth, inner).size(), 2u);
    const Topology t0 = mask_topology(s.mask), t_tube = mask_topology(with(s.mask, tube)), t_drill = mask_topology(with(s.mask, drill));
    ASSERT_EQ(t_tube.euler_solid, t0.euler_solid + 1);
    ASSERT_EQ(t_drill.euler_solid, t0.euler_solid + 1);
    ASSERT_EQ(t_tube.genus, t0.genus);  // ... the tube's fill only seals the pocket off
    // The walled-off pocket is counted in, nothing else.
    const Grid<std::uint8_t> enclosed = with_walled_inner(s.mask, inner);
    std::size_t added = 0;
    for (PointIndex i = 0; i < enclosed.size(); ++i) {
        if (enclosed[i] != s.mask[i]) {
            ++added;
            ASSERT_TRUE(in_pocket(s.mask.lattice().coord(i)));
        }
    }
    EXPECT_EQ(added, 28u);
    const std::vector<HoleSite> sites = truth_hole_sites(s.mask, truth, inner);
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_GT(sites[0].position.x, kCentre.x + kCore);  // the drill, not the tube
    const auto dv = drill.values();
    EXPECT_EQ(sites[0].voxels, static_cast<std::size_t>(std::count(dv.begin(), dv.end(), std::uint8_t{1})));
    // The drill filled: nothing left to find, and the truth's topology (the tube is a dent).
    const Grid<std::uint8_t> repaired = with(s.mask, drill);
    EXPECT_TRUE(truth_hole_sites(repaired, truth, inner, HoleAim::kOpening).empty());
    const Topology tr = mask_topology(truth), rep = mask_topology(repaired);
    EXPECT_EQ(rep.components, tr.components);
    EXPECT_EQ(rep.cavities, tr.cavities);
    EXPECT_EQ(rep.genus, tr.genus);
    EXPECT_THROW(with_walled_inner(s.mask, Grid<std::uint8_t>(Lattice({4, 4, 4}), 0)), std::invalid_argument);
}

TEST(SheetRepair, BadOptionsThrow) {
    SwarmOptions o;
    o.decision = EditDecision::kSheet;
    o.sheet_lower = 0.6;
    o.sheet_upper = 0.4;
    EXPECT_THROW(validate(o), std::invalid_argument);
    RepairScheduleOptions so;
    so.round_steps = 0;
    EXPECT_THROW(so.validate(), std::invalid_argument);
    EXPECT_THROW(hole_brush_range(10, 0.0), std::invalid_argument);
}

TEST(SheetRepair, BrushSizedToTheHole) {
    EXPECT_DOUBLE_EQ(hole_brush_range(0), 3.0);
    EXPECT_DOUBLE_EQ(hole_brush_range(1000000), 8.0);
    const double v = 3.0 * std::numbers::pi * 16.0;  // a disc of radius 4 through a 3-voxel shell
    EXPECT_NEAR(hole_brush_range(static_cast<std::size_t>(std::lround(v))), 5.0, 0.02);
}

}  // namespace
}  // namespace liveset

namespace liveset {
namespace {

// A flat sheet (GM, z in [15, 18)) over white matter (z < 15) under CSF, punched by a hole of
// radius 3 whose voxels read as white matter (a bias): every hole voxel lies between the sheet's
// two sides; the white matter under it and the CSF over it do not; nor does the CSF of a sulcus
// between two banks with white matter behind each.
TEST(SheetRepair, BetweenTheSheetsSidesIsTheHoleOnly) {
    const Lattice lat({40, 40, 40});
    Grid<float> image(lat, kCsf), phi(lat, 1.0f);
    const auto in_hole = [](Vec3i p) { return std::hypot(p.x - 20.0, p.y - 20.0) <= 3.0; };
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const Vec3i p{x, y, z};
                if (z < 15) image(p) = kWm;
                else if (z < 18) {
                    image(p) = in_hole(p) ? kWm : kGm;
                    if (!in_hole(p)) phi(p) = -1.0f;
                }
            }
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const Vec3i p{x, y, z};
                const bool hole = z >= 15 && z < 18 && in_hole(p);
                if (phi(p) < 0.0f) continue;
                // Within 8 voxels of the hole's axis (the reach), brute force over the region.
                if (std::hypot(x - 20.0, y - 20.0) > 8.0 || z < 8 || z > 25) continue;
                ASSERT_EQ(between_sheet_sides(phi, image, p, 8.0, kLower, kUpper), hole) << x << "," << y << "," << z;
            }
    // A sulcus: banks z in [10, 13) and [16, 19) with white matter behind each, CSF between.
    Grid<float> sulcus(lat, kCsf), sphi(lat, 1.0f);
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const Vec3i p{x, y, z};
                const bool bank = (z >= 10 && z < 13) || (z >= 16 && z < 19);
                sulcus(p) = bank ? kGm : (z < 10 || z >= 19 ? kWm : kCsf);
                if (bank) sphi(p) = -1.0f;
            }
    for (int z = 13; z < 16; ++z) EXPECT_FALSE(between_sheet_sides(sphi, sulcus, {20, 20, z}, 8.0, kLower, kUpper)) << z;
}

// The drilled shell with the drill's tissue reading `drill_value` (a bias moved it out of the band).
struct BrightDrill {
    Shell shell = drilled_shell(3.0);
    Grid<std::uint8_t> drill{shell.mask.lattice(), 0};
    explicit BrightDrill(float drill_value) {
        for (PointIndex i = 0; i < drill.size(); ++i)
            if (shell.image[i] == kGm && !shell.mask[i]) {
                drill[i] = 1;
                shell.image[i] = drill_value;
            }
    }
    // The hole is open while the shell encloses no cavity (one drill makes it a cap); its size is
    // the drill voxels still missing.
    HoleSiteFinder finder() const {
        return [this](const SparseField& f) {
            const Grid<std::uint8_t> m = inside_mask(f.phi());
            std::size_t missing = 0;
            for (PointIndex i = 0; i < m.size(); ++i) missing += drill[i] && !m[i];
            if (mask_topology(m).cavities == 1) return std::vector<HoleSite>{};
            return std::vector<HoleSite>{{Vec3d{kCentre.x + 23, kCentre.y, kCentre.z}, missing}};
        };
    }
    // `rounds` rounds of 200 steps of `ro` from the drilled mask, aimed by finder(): the schedule's
    // result and the mask after.
    std::pair<RepairScheduleResult, Grid<std::uint8_t>> repair(const RepairOptions& ro, int rounds) const {
        SparseField field(shell.mask.lattice(), 2);
        field.init_from_mask(shell.mask);
        RepairScheduleOptions so;
        so.rounds = rounds;
        so.round_steps = 200;
        RepairScheduleResult r = run_repair_schedule(field, shell.image, nullptr, ro, so, finder());
        return {std::move(r), inside_mask(field.phi())};
    }
};

// The drilled shell with its drill reading above the band (bias-bright hole tissue, as in the
// phantom): the band alone cannot close it; between the sheet's sides it closes, and every voxel
// added is one of the drill's.
TEST(SheetRepair, ClosesABiasBrightHoleAddingOnlyTheHolesVoxels) {
    // 0.7: above the band [0.35, 0.65), still more than a quarter the sheet's tissue (below 0.725).
    const BrightDrill b(0.7f);
    const Shell& s = b.shell;
    const Grid<std::uint8_t>& drill = b.drill;
    for (bool between : {false, true}) {
        RepairOptions ro = sheet_options();
        ro.swarm.sheet_between = between;
        const auto [r, after] = b.repair(ro, 5);
        if (!between) {
            EXPECT_GT(r.holes_left, 0u);  // nothing in the drill is in the band
            continue;
        }
        EXPECT_EQ(r.holes_left, 0u);
        EXPECT_EQ(mask_topology(after).genus, 0);
        EXPECT_EQ(mask_topology(after).cavities, 1u);  // sealed: the core enclosed again
        std::size_t drilled = 0, filled = 0;
        for (PointIndex i = 0; i < after.size(); ++i) {
            drilled += drill[i];
            filled += drill[i] && after[i];
            if (after[i] && !s.mask[i]) {
                ASSERT_TRUE(drill[i]) << "added a voxel outside the hole at " << s.mask.lattice().coord(i).x;
            }
        }
        EXPECT_GE(2 * filled, drilled);  // at least half the hole's tissue restored
    }
}

// sheet_between_range: the band widened towards each neighbouring class mean (2·edge − mean) so that
// a voxel holds at least the given share of the sheet's tissue by the partial-volume model.
TEST(SheetRepair, BetweenRangeHoldsTheSheetsShare) {
    SwarmOptions o = sheet_options().swarm;
    const auto expect = [&](double lo, double hi) {
        const auto [l, h] = sheet_between_range(o);
        EXPECT_NEAR(l, lo, 1e-12);
        EXPECT_NEAR(h, hi, 1e-12);
    };
    expect(0.275, 0.725);  // the default quarter, mean at the band's centre
    o.sheet_between_share = 0.5;
    expect(kLower, kUpper);  // half: the band itself
    o.sheet_between_share = 0.0;
    expect(0.2, 0.8);  // nothing: up to the neighbouring class means (kCsf, kWm)
    o.sheet_between_share = 0.25;
    o.sheet_mean = 0.45;  // CSF at 0.25, WM at 0.85: a quarter GM reads 0.30 and 0.75
    expect(0.30, 0.75);
    o.sheet_mean = 0.7;  // outside the band
    EXPECT_THROW(validate(o), std::invalid_argument);
    o.sheet_mean = 0.45;
    o.sheet_between_share = 0.6;
    EXPECT_THROW(validate(o), std::invalid_argument);
}

// A drill whose voxels read 0.76, under 15 % the sheet's tissue by the partial-volume model (kWm
// 0.8, kGm 0.5), is not the hole's tissue by intensity: between the sides or not, the default rule
// (at least a quarter) adds none of it; admitting up to the class means (share 0) closes it.
TEST(SheetRepair, AVoxelMostlyTheEnclosedTissueIsNotAdded) {
    const BrightDrill b(0.76f);
    for (double share : {0.25, 0.0}) {
        RepairOptions ro = sheet_options();
        ro.swarm.sheet_between_share = share;
        const auto [r, after] = b.repair(ro, 3);
        std::size_t added = 0;
        for (PointIndex i = 0; i < after.size(); ++i) added += after[i] && !b.shell.mask[i];
        if (share > 0) {
            EXPECT_GT(r.holes_left, 0u);
            EXPECT_EQ(added, 0u);
        } else {
            EXPECT_EQ(r.holes_left, 0u);
            EXPECT_EQ(mask_topology(after).cavities, 1u);
        }
    }
    // Reading as the white matter itself (the phantom's bias bumps): only without the limit.
    const BrightDrill w(kWm);
    RepairOptions ro = sheet_options();
    ro.swarm.sheet_between_limited = false;
    EXPECT_EQ(w.repair(ro, 3).first.holes_left, 0u);
}

// HoleSite::stalled_rounds, as the round's setup sees it: the band-only rule cannot raise the
// bias-bright drill, so every round stalls at the one hole and round r is told r earlier rounds
// stalled there (counted here from the finder's answers before and after each round).
TEST(SheetRepair, EachRoundIsToldHowOftenItsHoleStalled) {
    Shell s = drilled_shell(3.0);
    Grid<std::uint8_t> drill(s.mask.lattice(), 0);
    for (PointIndex i = 0; i < drill.size(); ++i)
        if (s.image[i] == kGm && !s.mask[i]) {
            drill[i] = 1;
            s.image[i] = kWm;
        }
    std::vector<std::size_t> sizes;  // the hole's size at each call of the finder
    const HoleSiteFinder find = [&](const SparseField& f) {
        const Grid<std::uint8_t> m = inside_mask(f.phi());
        std::size_t missing = 0;
        for (PointIndex i = 0; i < m.size(); ++i) missing += drill[i] && !m[i];
        sizes.push_back(missing);
        return std::vector<HoleSite>{{Vec3d{kCentre.x + 23, kCentre.y, kCentre.z}, missing}};
    };
    std::vector<int> told;
    const RoundSetup setup = [&](RepairOptions&, const HoleSite& t) { told.push_back(t.stalled_rounds); };
    SparseField field(s.mask.lattice(), 2);
    field.init_from_mask(s.mask);
    RepairOptions ro = sheet_options();
    ro.swarm.sheet_between = false;
    RepairScheduleOptions so;
    so.rounds = 4;
    so.round_steps = 30;
    run_repair_schedule(field, s.image, nullptr, ro, so, find, setup);
    ASSERT_EQ(told.size(), 4u);
    ASSERT_EQ(sizes.size(), 5u);
    int stalled = 0;
    for (std::size_t r = 0; r < told.size(); ++r) {
        EXPECT_EQ(told[r], stalled) << "round " << r;
        stalled += static_cast<double>(sizes[r + 1]) > 0.95 * static_cast<double>(sizes[r]);
    }
    EXPECT_EQ(stalled, 4);  // nothing in the drill is in the band
}

}  // namespace
}  // namespace liveset
