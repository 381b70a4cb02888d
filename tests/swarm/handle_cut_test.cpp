// Cutting handles (EditDecision::kCut, GuardOptions::cut_handles, find_inner_handles): a shell
// whose mask took in a rod of the tissue it encloses (a handle across the core), checked against
// brute-force topology of every candidate removal.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "liveset/eval/perforations.hpp"
#include "liveset/grid/digital_topology.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/swarm/repair_schedule.hpp"

namespace liveset {
namespace {

constexpr int kCutN = 32;
const Vec3i kCutC{16, 16, 16};
constexpr double kCutCore = 9, kCutOuter = 12;

// inner: the ball r <= kCutCore; truth: the shell kCutCore < r <= kCutOuter; the mask: the shell plus what
// the case adds.
struct Case {
    Grid<std::uint8_t> mask{Lattice({kCutN, kCutN, kCutN}), 0}, truth{Lattice({kCutN, kCutN, kCutN}), 0}, inner{Lattice({kCutN, kCutN, kCutN}), 0};
    std::vector<Vec3i> handle;  // the voxels a cut may remove
};

bool same(const Grid<std::uint8_t>& a, const Grid<std::uint8_t>& b) {
    return std::ranges::equal(a.values(), b.values());
}

double radius(Vec3i q) { return norm((q - kCutC).cast<double>()); }

Case shell() {
    Case c;
    for (int z = 0; z < kCutN; ++z)
        for (int y = 0; y < kCutN; ++y)
            for (int x = 0; x < kCutN; ++x) {
                const double r = radius({x, y, z});
                c.inner({x, y, z}) = r <= kCutCore;
                c.truth({x, y, z}) = c.mask({x, y, z}) = r > kCutCore && r <= kCutOuter;
            }
    return c;
}

// A one-voxel rod of inner tissue across the core along x (a handle: genus 1), and a bump of inner
// tissue on the shell's inner face at −y (no handle).
Case rod_and_bump() {
    Case c = shell();
    for (int x = 0; x < kCutN; ++x)
        if (c.inner({x, 16, 16})) {
            c.mask({x, 16, 16}) = 1;
            c.handle.push_back({x, 16, 16});
        }
    for (int z = 14; z <= 18; ++z)
        for (int x = 14; x <= 18; ++x)
            for (int y = 7; y <= 9; ++y)
                if (c.inner({x, y, z}) && radius({x, y, z}) > kCutCore - 1.5) c.mask({x, y, z}) = 1;
    return c;
}

// A blob of the mask in the core (not inner tissue) held to the shell by a one-voxel bridge of
// inner tissue along +z: removing a bridge voxel splits the blob off.
Case blob_on_a_bridge() {
    Case c = shell();
    for (int z = 15; z <= 17; ++z)
        for (int y = 15; y <= 17; ++y)
            for (int x = 15; x <= 17; ++x) {
                c.mask({x, y, z}) = 1;
                c.inner({x, y, z}) = 0;
            }
    for (int z = 18; z < kCutN && c.inner({16, 16, z}); ++z) c.mask({16, 16, z}) = 1;
    return c;
}

Grid<std::uint8_t> without(Grid<std::uint8_t> m, const std::vector<PointIndex>& points) {
    for (PointIndex i : points) m[i] = 0;
    return m;
}

// Brute force: removing `points` cuts a handle (genus down, pieces and cavities unchanged).
bool cuts(const Grid<std::uint8_t>& mask, const std::vector<PointIndex>& points) {
    const Topology a = mask_topology(mask), b = mask_topology(without(mask, points));
    return b.genus < a.genus && b.components == a.components && b.cavities == a.cavities;
}

TEST(HandleCut, FinderListsTheInnerHandlesAndNothingElse) {
    for (const Case& c : {rod_and_bump(), blob_on_a_bridge()}) {
        Grid<std::uint8_t> taken(c.mask.lattice(), 0);
        for (PointIndex i = 0; i < taken.size(); ++i) taken[i] = c.mask[i] && c.inner[i];
        std::size_t count = 0;
        const ComponentLabels label = label_components(taken, 26, &count);
        std::vector<std::vector<PointIndex>> region(count + 1);
        for (PointIndex i = 0; i < taken.size(); ++i) region[label[i]].push_back(i);
        std::size_t expected = 0;
        for (std::size_t k = 1; k <= count; ++k) expected += cuts(c.mask, region[k]);
        const std::vector<Perforation> found = find_inner_handles(c.mask, c.inner);
        ASSERT_EQ(found.size(), expected);
        for (const Perforation& p : found) {
            const std::uint32_t k = label[c.mask.lattice().index(p.nearest)];
            ASSERT_NE(k, 0u);
            EXPECT_TRUE(cuts(c.mask, region[k]));
            EXPECT_EQ(p.voxels, region[k].size());
        }
    }
    // The rod is the one handle; the bridge's removal splits the blob off: none.
    const Case a = rod_and_bump();
    ASSERT_EQ(mask_topology(a.mask).genus, 1);
    const std::vector<Perforation> found = find_inner_handles(a.mask, a.inner);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].voxels, a.handle.size());
    EXPECT_TRUE(find_inner_handles(blob_on_a_bridge().mask, blob_on_a_bridge().inner).empty());
    EXPECT_THROW(find_inner_handles(a.mask, Grid<std::uint8_t>(Lattice({4, 4, 4}), 0)), std::invalid_argument);
    // The truth finder lists it last, as a site to cut on the rod.
    const std::vector<HoleSite> sites = truth_hole_sites(a.mask, a.truth, a.inner);
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_TRUE(sites[0].cut);
    EXPECT_EQ(sites[0].position.y, 16.0);
    EXPECT_EQ(sites[0].position.z, 16.0);
}

TEST(HandleCut, GuardKeepsExactlyTheRemovalsThatCutAHandle) {
    for (const Case& c : {rod_and_bump(), blob_on_a_bridge()}) {
        SparseField field(c.mask.lattice(), 2);
        field.init_from_mask(c.mask);
        ASSERT_TRUE(same(inside_mask(field.phi()), c.mask));
        GuardOptions go;
        go.cut_handles = true;
        std::size_t tried = 0;
        std::vector<Vec3i> kept;
        for (PointIndex i = 0; i < c.mask.size(); ++i) {
            if (field.status()[i] != 0 || !(field.phi()[i] < 0.0f)) continue;
            std::vector<ZeroLayerEdit> edits{{i, 0.5f}};  // flips every inside zero-layer point
            ++tried;
            const std::size_t dropped = guard_topology(field, edits, go);
            const bool cut = cuts(c.mask, {i});
            ASSERT_EQ(dropped == 0, cut) << "point " << i;
            if (cut) kept.push_back(c.mask.lattice().coord(i));
        }
        EXPECT_GT(tried, 1000u);
        // Only rod voxels cut it (most of them); the bridge's would split the blob off.
        EXPECT_GE(kept.size(), c.handle.size() / 2);
        for (const Vec3i q : kept) EXPECT_NE(std::find(c.handle.begin(), c.handle.end(), q), c.handle.end());
        // Edits that flip nothing pass only where a cut may come (two inside pieces around the point).
        std::vector<ZeroLayerEdit> small;
        std::size_t candidates = 0;
        for (PointIndex i = 0; i < c.mask.size(); ++i)
            if (field.status()[i] == 0 && field.phi()[i] < -0.4f) {
                small.push_back({i, 0.1f});
                const Vec3i q = c.mask.lattice().coord(i);
                candidates += topological_numbers([&](Vec3i r) { return c.mask.lattice().contains(r) && c.mask(r) != 0; }, q).foreground >= 2;
            }
        ASSERT_FALSE(small.empty());
        EXPECT_EQ(guard_topology(field, small, go), small.size() - candidates) << "kept only the candidates";
    }
    // One batch removing the whole rod: the flips accepted earlier in the batch count (the first
    // cut leaves the rest of the rod no handle), so the rod is cut once and nothing splits off.
    const Case a = rod_and_bump();
    SparseField field(a.mask.lattice(), 2);
    field.init_from_mask(a.mask);
    std::vector<ZeroLayerEdit> rod;
    for (const Vec3i q : a.handle) rod.push_back({a.mask.lattice().index(q), 0.5f});
    GuardOptions go;
    go.cut_handles = true;
    EXPECT_EQ(guard_topology(field, rod, go), a.handle.size() - 1);
    ASSERT_EQ(rod.size(), 1u);
    field.apply_edits(rod, RepairScope::kLocal);
    const Topology t = mask_topology(inside_mask(field.phi()));
    EXPECT_EQ(t.genus, 0);
    EXPECT_EQ(t.components, 1u);
    EXPECT_EQ(t.cavities, 1u);
}

RepairOptions cut_options() {
    RepairOptions ro;
    ro.swarm.decision = EditDecision::kCut;
    ro.swarm.edit_range = 3.0;
    ro.swarm.act_probability = 0.3;
    return ro;
}

TEST(HandleCut, TheSwarmCutsTheHandleAndRemovesNothingElse) {
    const Case a = rod_and_bump();
    SparseField field(a.mask.lattice(), 2);
    field.init_from_mask(a.mask);
    // The schedule with the truth finder: the rod is the one site; one round cuts it.
    const HoleSiteFinder find = [&](const SparseField& f) { return truth_hole_sites(inside_mask(f.phi()), a.truth, a.inner); };
    RepairScheduleOptions so;
    so.rounds = 3;
    const RepairScheduleResult r = run_repair_schedule(field, Grid<float>(a.mask.lattice(), 0.5f), nullptr, cut_options(), so, find);
    EXPECT_EQ(r.holes_left, 0u);
    ASSERT_GE(r.rounds.size(), 1u);
    const Grid<std::uint8_t> after = inside_mask(field.phi());
    const Topology t = mask_topology(after), truth = mask_topology(a.truth);
    EXPECT_EQ(t.genus, 0);
    EXPECT_EQ(t.components, truth.components);
    EXPECT_EQ(t.cavities, truth.cavities);
    std::size_t removed = 0;
    for (PointIndex i = 0; i < after.size(); ++i) {
        ASSERT_FALSE(after[i] && !a.mask[i]) << "a cut adds nothing";
        if (a.mask[i] && !after[i]) {
            ++removed;
            ASSERT_NE(std::find(a.handle.begin(), a.handle.end(), a.mask.lattice().coord(i)), a.handle.end()) << "removed a voxel off the rod";
        }
    }
    EXPECT_GE(removed, 1u);
}

TEST(HandleCut, NoCutWhereThereIsNoHandleOrWhereItWouldSplit) {
    for (const auto& [c, target] : {std::pair{rod_and_bump(), Vec3d{16, 16, 27}}, std::pair{blob_on_a_bridge(), Vec3d{16, 16, 22}}}) {
        SparseField field(c.mask.lattice(), 2);
        field.init_from_mask(c.mask);
        RepairOptions ro = cut_options();
        ro.steps = 150;
        const std::vector<RepairTarget> targets{{target, 0}};
        const Grid<float> phi_before = field.phi();
        run_repair(field, Grid<float>(c.mask.lattice(), 0.5f), nullptr, targets, ro);
        EXPECT_TRUE(same(inside_mask(field.phi()), c.mask));
        // On the plain shell (no point with two inside pieces in the brush) φ does not move at all.
        if (!c.handle.empty()) {
            EXPECT_TRUE(std::ranges::equal(field.phi().values(), phi_before.values()));
        }
    }
}

TEST(HandleCut, BadOptionsThrow) {
    RepairOptions ro = cut_options();
    ro.swarm.edit_range = 0.0;
    EXPECT_THROW(validate(ro.swarm), std::invalid_argument);
    ro = cut_options();
    ro.topology_guard = false;
    const Case a = rod_and_bump();
    SparseField field(a.mask.lattice(), 2);
    field.init_from_mask(a.mask);
    const Grid<float> image(a.mask.lattice(), 0.5f);
    EXPECT_THROW(RepairLoop(field, image, nullptr, ro), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
