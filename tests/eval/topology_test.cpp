// Topology: Euler characteristic, components, cavities and genus of hand-countable shapes (voxel,
// ball, torus, shells with 1..4 drilled perforations, diagonal contacts, shapes on the image
// border), the paper's holes count, and the connected-component labelling.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "eval/mask_shapes.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/grid/digital_topology.hpp"

using namespace liveset;
using liveset::test::Mask;
using liveset::test::paint;
using liveset::test::paint_ball;
using liveset::test::paint_box;

namespace {

void expect_topology(const Topology& t, std::size_t components, std::size_t cavities, long euler_solid,
                     long genus) {
    EXPECT_EQ(t.components, components);
    EXPECT_EQ(t.cavities, cavities);
    EXPECT_EQ(t.euler_solid, euler_solid);
    EXPECT_EQ(t.euler, 2 * euler_solid);
    EXPECT_EQ(t.genus, genus);
}

// Thick spherical shell about the centre of a 28³ image: 6 < r <= 11 voxels.
Mask thick_shell() {
    Mask m(Lattice({28, 28, 28}, {1.0, 1.2, 0.9}));
    const Vec3d c{13.5, 13.5, 13.5};
    paint(m, [&](Vec3d p) {
        const double r = norm(p - c);
        return r > 6.0 && r <= 11.0;
    });
    return m;
}

// Drills a cylinder of radius 2 from the shell's centre out along one of ±x, ±y: one perforation
// through the wall each.
void drill(Mask& m, int which) {
    const Vec3d c{13.5, 13.5, 13.5};
    const int axis = which / 2;          // 0: x, 1: y
    const double sign = which % 2 ? -1 : 1;
    paint(m, [&](Vec3d p) {
        const Vec3d q = p - c;
        const double along = sign * q[axis];
        const double off_a = q[1 - axis];
        const double off_b = q.z;
        return along > 0 && off_a * off_a + off_b * off_b <= 4.0;
    }, 0);
}

}  // namespace

TEST(Topology, SingleVoxel) {
    Mask m(Lattice({5, 5, 5}));
    m({2, 2, 2}) = 1;
    expect_topology(mask_topology(m), 1, 0, 1, 0);
    EXPECT_EQ(mask_topology(m).euler, 2);
}

TEST(Topology, EmptyMask) {
    const Mask m(Lattice({4, 4, 4}));
    expect_topology(mask_topology(m), 0, 0, 0, 0);
}

TEST(Topology, SolidBall) {
    Mask m(Lattice({20, 20, 20}));
    paint_ball(m, {9.5, 9.5, 9.5}, 7.0);
    expect_topology(mask_topology(m), 1, 0, 1, 0);
}

TEST(Topology, TwoDisjointBalls) {
    Mask m(Lattice({30, 16, 16}));
    paint_ball(m, {7.5, 7.5, 7.5}, 5.0);
    paint_ball(m, {21.5, 7.5, 7.5}, 5.0);
    expect_topology(mask_topology(m), 2, 0, 2, 0);
    EXPECT_EQ(mask_topology(m).euler, 4);
}

TEST(Topology, SolidTorusHasGenusOne) {
    Mask m(Lattice({30, 30, 12}));
    const Vec3d c{14.5, 14.5, 5.5};
    paint(m, [&](Vec3d p) {
        const Vec3d q = p - c;
        const double ring = std::hypot(q.x, q.y) - 9.0;
        return ring * ring + q.z * q.z <= 3.5 * 3.5;
    });
    expect_topology(mask_topology(m), 1, 0, 0, 1);
    EXPECT_EQ(mask_topology(m).euler, 0);
}

TEST(Topology, SquareFrameAndDoubleFrame) {
    // A 10x10x3 slab with one 4x4 hole punched through: a box torus.
    Mask one(Lattice({14, 14, 7}));
    paint_box(one, {2, 2, 2}, {12, 12, 5});
    paint_box(one, {5, 5, 2}, {9, 9, 5}, 0);
    expect_topology(mask_topology(one), 1, 0, 0, 1);
    // Two holes: genus 2, χ = 1 - 2.
    Mask two(Lattice({20, 14, 7}));
    paint_box(two, {2, 2, 2}, {18, 12, 5});
    paint_box(two, {4, 5, 2}, {8, 9, 5}, 0);
    paint_box(two, {12, 5, 2}, {16, 9, 5}, 0);
    expect_topology(mask_topology(two), 1, 0, -1, 2);
}

TEST(Topology, ThickSphericalShell) {
    const Mask shell = thick_shell();
    const Topology t = mask_topology(shell);
    expect_topology(t, 1, 1, 2, 0);
    EXPECT_EQ(t.euler, 4);
    EXPECT_EQ(holes_between(t, t), 0);
}

TEST(Topology, EachPerforationOfTheShellIsOneHole) {
    const Topology closed = mask_topology(thick_shell());
    Mask perforated = thick_shell();
    for (int k = 1; k <= 4; ++k) {
        drill(perforated, k - 1);
        const Topology t = mask_topology(perforated);
        SCOPED_TRACE("perforations: " + std::to_string(k));
        // Opening the shell merges the cavity with the outside; every further opening adds a tunnel.
        expect_topology(t, 1, 0, 2 - k, k - 1);
        EXPECT_EQ(t.euler, 4 - 2 * k);
        EXPECT_EQ(holes_between(closed, t), k);
        EXPECT_EQ(holes_between(t, closed), -k);
    }
}

TEST(Topology, DiagonalContactsAreOneComponent) {
    // Corner contact: 8+8-1 vertices, 24 edges, 12 faces, 2 cubes: χ = 1.
    Mask corner(Lattice({6, 6, 6}));
    corner({2, 2, 2}) = 1;
    corner({3, 3, 3}) = 1;
    expect_topology(mask_topology(corner), 1, 0, 1, 0);
    // Edge contact: 14 vertices, 23 edges, 12 faces, 2 cubes: χ = 1.
    Mask edge(Lattice({6, 6, 6}));
    edge({2, 2, 2}) = 1;
    edge({3, 3, 2}) = 1;
    expect_topology(mask_topology(edge), 1, 0, 1, 0);
    // Three voxels pairwise sharing an edge, all three edges meeting in the corner (3,3,3): the
    // union is star-shaped about that corner, hence contractible (no tunnel through the pinch).
    Mask ring(Lattice({6, 6, 6}));
    ring({2, 2, 2}) = 1;
    ring({3, 3, 2}) = 1;
    ring({2, 3, 3}) = 1;
    expect_topology(mask_topology(ring), 1, 0, 1, 0);
}

TEST(Topology, ShapesOnTheImageBorder) {
    // A box in the image corner: outside the image is background, so it is still a ball.
    Mask corner(Lattice({10, 10, 10}));
    paint_box(corner, {0, 0, 0}, {4, 4, 4});
    expect_topology(mask_topology(corner), 1, 0, 1, 0);
    // The whole image foreground, including a 1x1x1 image.
    expect_topology(mask_topology(Mask(Lattice({7, 5, 3}), 1)), 1, 0, 1, 0);
    expect_topology(mask_topology(Mask(Lattice({1, 1, 1}), 1)), 1, 0, 1, 0);
    // Image-filling box with a hidden 4³ hollow: one cavity, χ = 2.
    Mask hollow(Lattice({8, 8, 8}), 1);
    paint_box(hollow, {2, 2, 2}, {6, 6, 6}, 0);
    expect_topology(mask_topology(hollow), 1, 1, 2, 0);
    // Image-filling box with a tunnel of background running out through two border faces: the
    // tunnel's background touches the border, so it is no cavity; the solid is a torus.
    Mask tunnel(Lattice({8, 8, 8}), 1);
    for (int x = 0; x < 8; ++x) tunnel({x, 4, 4}) = 0;
    expect_topology(mask_topology(tunnel), 1, 0, 0, 1);
    // A background pocket open to one border face only is no cavity and no tunnel, whichever of
    // the six faces it opens onto.
    for (int face = 0; face < 6; ++face) {
        SCOPED_TRACE("pocket open to face " + std::to_string(face));
        const int axis = face / 2;
        Vec3i lo{3, 3, 3}, hi{5, 5, 5};
        if (face % 2 == 0) lo[axis] = 0; else hi[axis] = 8;
        Mask pocket(Lattice({8, 8, 8}), 1);
        paint_box(pocket, lo, hi, 0);
        expect_topology(mask_topology(pocket), 1, 0, 1, 0);
    }
    // Two boxes in opposite corners.
    Mask two(Lattice({9, 9, 9}));
    paint_box(two, {0, 0, 0}, {3, 3, 3});
    paint_box(two, {6, 6, 6}, {9, 9, 9});
    expect_topology(mask_topology(two), 2, 0, 2, 0);
}

TEST(Topology, CavitiesSealedAtAVoxelCornerStayCavities) {
    // Image-filling box with a 4³ hollow, plus background voxels (1,1,1) and (0,0,0) forming a
    // corner-to-corner chain from the hollow out to the image border. Closed voxel cubes seal every
    // corner contact, so with 6-connected background there are two cavities (the hollow and the
    // single voxel (1,1,1)) and (0,0,0) is just a notch in the border: χ = 1 + 2, genus 0.
    Mask m(Lattice({8, 8, 8}), 1);
    paint_box(m, {2, 2, 2}, {6, 6, 6}, 0);
    m({1, 1, 1}) = 0;
    m({0, 0, 0}) = 0;
    expect_topology(mask_topology(m), 1, 2, 3, 0);
}

TEST(Topology, DoesNotDependOnThreadCount) {
    Mask perforated = thick_shell();
    drill(perforated, 0);
    drill(perforated, 2);
    const Topology parallel = mask_topology(perforated);
    Topology serial;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        serial = mask_topology(perforated);
    }
    EXPECT_EQ(parallel.euler_solid, serial.euler_solid);
    EXPECT_EQ(parallel.components, serial.components);
    EXPECT_EQ(parallel.cavities, serial.cavities);
}

TEST(LabelComponents, ConnectivityDecidesDiagonalContacts) {
    Mask m(Lattice({6, 6, 6}));
    m({2, 2, 2}) = 1;
    m({3, 3, 3}) = 1;
    std::size_t count = 0;
    ComponentLabels six = label_components(m, 6, &count);
    EXPECT_EQ(count, 2u);
    EXPECT_EQ(six[m.lattice().index({2, 2, 2})], 1u);
    EXPECT_EQ(six[m.lattice().index({3, 3, 3})], 2u);
    ComponentLabels all = label_components(m, 26, &count);
    EXPECT_EQ(count, 1u);
    EXPECT_EQ(all[m.lattice().index({3, 3, 3})], 1u);
    EXPECT_EQ(all[m.lattice().index({0, 0, 0})], 0u);
    EXPECT_NO_THROW(label_components(m, 26, nullptr));
}

TEST(LabelComponents, LabelsFollowScanOrderOfFirstVoxel) {
    Mask m(Lattice({10, 6, 6}));
    paint_box(m, {6, 0, 0}, {9, 2, 2});  // first voxel (6,0,0): label 1
    paint_box(m, {0, 4, 0}, {3, 6, 6});  // first voxel (0,4,0): label 2
    paint_box(m, {5, 3, 2}, {9, 6, 6});  // first voxel (5,3,2): label 3 (6-separated from the others)
    std::size_t count = 0;
    const ComponentLabels labels = label_components(m, 6, &count);
    ASSERT_EQ(count, 3u);
    const Lattice& lat = m.lattice();
    EXPECT_EQ(labels[lat.index({8, 1, 1})], 1u);
    EXPECT_EQ(labels[lat.index({2, 5, 5})], 2u);
    EXPECT_EQ(labels[lat.index({8, 5, 5})], 3u);
    // Every foreground voxel is labelled, every background voxel is 0, and the box sizes add up.
    std::vector<std::size_t> sizes(count + 1, 0);
    for (PointIndex i = 0; i < m.size(); ++i) {
        EXPECT_EQ(labels[i] == 0, m[i] == 0);
        ++sizes[labels[i]];
    }
    EXPECT_EQ(sizes[1], 12u);
    EXPECT_EQ(sizes[2], 36u);
    EXPECT_EQ(sizes[3], 48u);
}

TEST(LabelComponents, MergedBranchesGetOneCompactLabel) {
    // A U: two pillars that only join at z = 3, seen as separate pieces until then, and a lone
    // pillar that starts on the first slice between them in scan order.
    Mask m(Lattice({9, 3, 5}));
    paint_box(m, {1, 1, 0}, {2, 2, 4});  // left arm
    paint_box(m, {4, 1, 0}, {5, 2, 4});  // right arm
    paint_box(m, {1, 1, 3}, {5, 2, 4});  // bar joining them on top
    paint_box(m, {7, 1, 0}, {8, 2, 5});  // separate pillar
    for (int connectivity : {6, 26}) {
        std::size_t count = 0;
        const ComponentLabels labels = label_components(m, connectivity, &count);
        EXPECT_EQ(count, 2u);
        const Lattice& lat = m.lattice();
        EXPECT_EQ(labels[lat.index({1, 1, 0})], 1u);
        EXPECT_EQ(labels[lat.index({4, 1, 0})], 1u);
        EXPECT_EQ(labels[lat.index({3, 1, 3})], 1u);
        EXPECT_EQ(labels[lat.index({7, 1, 0})], 2u);
        EXPECT_EQ(labels[lat.index({7, 1, 4})], 2u);
        EXPECT_EQ(*std::max_element(labels.begin(), labels.end()), 2u);
    }
}

// Labels by breadth-first flood fill from each unlabelled voxel in scan order: the definition the
// run-length labelling must reproduce exactly (numbers included).
ComponentLabels flood_labels(const Mask& m, int connectivity, std::size_t& count) {
    const Lattice& lat = m.lattice();
    ComponentLabels label(m.size(), 0);
    count = 0;
    std::vector<PointIndex> queue;
    for (PointIndex s = 0; s < m.size(); ++s) {
        if (m[s] == 0 || label[s] != 0) continue;
        label[s] = static_cast<std::uint32_t>(++count);
        queue.assign(1, s);
        while (!queue.empty()) {
            const Vec3i p = lat.coord(queue.back());
            queue.pop_back();
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int steps = std::abs(dx) + std::abs(dy) + std::abs(dz);
                        if (steps == 0 || (connectivity == 6 && steps > 1)) continue;
                        const Vec3i q{p.x + dx, p.y + dy, p.z + dz};
                        if (!lat.contains(q) || m(q) == 0 || label[lat.index(q)] != 0) continue;
                        label[lat.index(q)] = static_cast<std::uint32_t>(count);
                        queue.push_back(lat.index(q));
                    }
        }
    }
    return label;
}

TEST(LabelComponents, MatchesAFloodFillOnRandomMasks) {
    std::mt19937 rng(7);
    for (double density : {0.2, 0.45, 0.6}) {
        Mask m(Lattice({17, 11, 9}));
        std::bernoulli_distribution on(density);
        for (std::uint8_t& v : m.values()) v = on(rng) ? 1 : 0;
        for (int connectivity : {6, 26}) {
            std::size_t count = 0, expected_count = 0;
            const ComponentLabels labels = label_components(m, connectivity, &count);
            const ComponentLabels expected = flood_labels(m, connectivity, expected_count);
            EXPECT_EQ(count, expected_count) << density << " " << connectivity;
            EXPECT_TRUE(labels == expected) << density << " " << connectivity;
        }
    }
}

TEST(LabelComponents, RejectsUnsupportedConnectivity) {
    const Mask m(Lattice({3, 3, 3}));
    EXPECT_THROW(label_components(m, 18, nullptr), std::invalid_argument);
    EXPECT_THROW(label_components(m, 4, nullptr), std::invalid_argument);
}

// find_perforations: the drilled tunnels of a shell, located; a dent that does not go through is
// not one.
TEST(Perforations, FindsEachDrilledTunnelAndNotADent) {
    const Mask truth = thick_shell();
    Mask inner(truth.lattice(), 0);
    paint(inner, [](Vec3d p) { return norm(p - Vec3d{13.5, 13.5, 13.5}) <= 6.0; });
    Mask mask = truth;
    drill(mask, 0);  // +x
    drill(mask, 3);  // -y
    // A dent from outside along +z that stops half way through the wall.
    paint(mask, [](Vec3d p) {
        const Vec3d q = p - Vec3d{13.5, 13.5, 13.5};
        return q.z > 8.5 && q.x * q.x + q.y * q.y <= 4.0;
    }, 0);
    const auto found = find_perforations(mask, truth, inner);
    ASSERT_EQ(found.size(), 2u);
    for (const Perforation& p : found) {
        EXPECT_GT(p.voxels, 10u);
        EXPECT_TRUE(truth(p.nearest) && !mask(p.nearest));
        const Vec3d d = p.centroid - Vec3d{13.5, 13.5, 13.5};
        const bool along_x = d.x > 5 && std::abs(d.y) < 1.5 && std::abs(d.z) < 1.5;
        const bool along_minus_y = d.y < -5 && std::abs(d.x) < 1.5 && std::abs(d.z) < 1.5;
        EXPECT_TRUE(along_x || along_minus_y) << d.x << "," << d.y << "," << d.z;
    }
    EXPECT_TRUE(find_perforations(truth, truth, inner).empty());
    EXPECT_THROW(find_perforations(mask, truth, Mask(Lattice({4, 4, 4}), 0)), std::invalid_argument);
}

// find_cavities: bubbles carved inside the shell's wall are found and located, largest first; the
// shell's own core (the inner tissue) and a perforation (open to the outside) are not cavities.
TEST(Perforations, FindsBubblesInTheWallButNotTheCore) {
    const Mask truth = thick_shell();
    Mask inner(truth.lattice(), 0);
    paint(inner, [](Vec3d p) { return norm(p - Vec3d{13.5, 13.5, 13.5}) <= 6.0; });
    Mask mask = truth;
    EXPECT_TRUE(find_cavities(mask, inner).empty());  // the core is the shell's legitimate cavity
    const Vec3i one{13, 13, 22};                        // a one-voxel bubble in the +z wall (r = 8.5)
    mask(one) = 0;
    paint(mask, [](Vec3d p) { return norm(p - Vec3d{13, 22, 13}) <= 1.0; }, 0);  // a 7-voxel bubble in +y
    drill(mask, 0);                                     // a perforation along +x: open, not a cavity
    ASSERT_EQ(mask_topology(mask).cavities, 2u);        // the core joined the outside through the tunnel
    const auto found = find_cavities(mask, inner);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(found[0].voxels, 7u);
    EXPECT_LT(norm(found[0].centroid - Vec3d{13, 22, 13}), 1e-9);
    EXPECT_EQ(found[1].voxels, 1u);
    EXPECT_EQ(found[1].nearest, one);
    EXPECT_THROW(find_cavities(mask, Mask(Lattice({4, 4, 4}), 0)), std::invalid_argument);
}

namespace {

// The local Euler characteristic (grid/digital_topology.hpp) against mask_topology, a separate
// count by component labelling (components − genus + cavities) on random masks: over the whole
// image it equals χ, and flipping a voxel changes χ over a box one voxel around it exactly as the
// whole mask's χ changes.
TEST(Topology, LocalEulerCharacteristicMatchesTheWholeMasks) {
    std::uint64_t s = 99;
    const auto next = [&] {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        return s >> 33;
    };
    for (int trial = 0; trial < 30; ++trial) {
        Mask m(Lattice({9, 8, 7}));
        for (PointIndex i = 0; i < m.size(); ++i) m[i] = next() % 100 < 30 + 2 * static_cast<unsigned>(trial);
        const auto inside = [&](Vec3i q) { return m.lattice().contains(q) && m(q) != 0; };
        const Topology t = mask_topology(m);
        const long chi = static_cast<long>(t.components) - t.genus + static_cast<long>(t.cavities);
        ASSERT_EQ(euler_characteristic_26(inside, {0, 0, 0}, {8, 7, 6}), chi) << "trial " << trial;
        const Vec3i p{static_cast<int>(next() % 9), static_cast<int>(next() % 8), static_cast<int>(next() % 7)};
        const Vec3i lo = p - Vec3i{1, 1, 1}, hi = p + Vec3i{1, 1, 1};
        const long local_before = euler_characteristic_26(inside, lo, hi);
        m(p) = m(p) ? 0 : 1;
        const Topology u = mask_topology(m);
        const long chi_after = static_cast<long>(u.components) - u.genus + static_cast<long>(u.cavities);
        EXPECT_EQ(euler_characteristic_26(inside, lo, hi) - local_before, chi_after - chi) << "trial " << trial;
        // Several voxels flipped at once (some at the border, some repeated), counted only at the
        // corner points around them (euler_corners_of): the same change as the whole mask's.
        std::vector<Vec3i> flips;
        for (int k = 0; k < 1 + trial % 7; ++k)
            flips.push_back({static_cast<int>(next() % 9), static_cast<int>(next() % 8), static_cast<int>(next() % 7)});
        flips.push_back(flips.front());
        const std::vector<Vec3i> corners = euler_corners_of(flips);
        const long at_corners_before = euler_at_corners_26(inside, corners);
        for (std::size_t k = 0; k + 1 < flips.size(); ++k) m(flips[k]) = m(flips[k]) ? 0 : 1;
        const Topology w = mask_topology(m);
        const long chi_flipped = static_cast<long>(w.components) - w.genus + static_cast<long>(w.cavities);
        EXPECT_EQ(euler_at_corners_26(inside, corners) - at_corners_before, chi_flipped - chi_after) << "trial " << trial;
    }
    // Hand counts: a voxel 1, a 3x3x1 ring (one tunnel) 0, a 3x3x3 hollow cube (one cavity) 2.
    Mask ring(Lattice({5, 5, 3}));
    paint_box(ring, {1, 1, 1}, {4, 4, 2});
    const auto in_ring = [&](Vec3i q) { return ring.lattice().contains(q) && ring(q) != 0; };
    EXPECT_EQ(euler_characteristic_26(in_ring, {0, 0, 0}, {4, 4, 2}), 1);
    ring({2, 2, 1}) = 0;
    EXPECT_EQ(euler_characteristic_26(in_ring, {0, 0, 0}, {4, 4, 2}), 0);
    Mask hollow(Lattice({5, 5, 5}));
    paint_box(hollow, {1, 1, 1}, {4, 4, 4});
    hollow({2, 2, 2}) = 0;
    const auto in_hollow = [&](Vec3i q) { return hollow.lattice().contains(q) && hollow(q) != 0; };
    EXPECT_EQ(euler_characteristic_26(in_hollow, {0, 0, 0}, {4, 4, 4}), 2);
}

}  // namespace

namespace {

// find_missed_tunnels: a pinhole through a plate (a tunnel no inner tissue lies under) is found,
// exactly its voxels; a dent in the same plate and a matching mask are not.
TEST(Perforations, MissedTunnelsAreThePinholesNotTheDents) {
    Mask truth(Lattice({12, 12, 7}));
    paint_box(truth, {1, 1, 2}, {11, 11, 5});
    Mask mask = truth;
    for (int z = 2; z < 5; ++z) mask({5, 6, z}) = 0;  // the pinhole: genus 1
    mask({2, 2, 4}) = 0;                               // a dent from the top face
    ASSERT_EQ(mask_topology(mask).genus, 1);
    const auto found = find_missed_tunnels(mask, truth);
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].voxels, 3u);
    EXPECT_EQ(found[0].nearest, (Vec3i{5, 6, 3}));
    EXPECT_TRUE(find_missed_tunnels(truth, truth).empty());
    EXPECT_THROW(find_missed_tunnels(mask, Mask(Lattice({4, 4, 4}), 0)), std::invalid_argument);
}

}  // namespace
