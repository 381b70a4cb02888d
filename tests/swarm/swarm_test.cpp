// Swarm: agents stay on the zero level set (analytic sphere), are attracted to a target while
// keeping apart, move tangentially, propose local expanding edits on a bright image, are
// bit-identical for 1 and 2 TBB threads, and reject bad options.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <iostream>
#include <vector>

#include "liveset/grid/sampling.hpp"
#include "liveset/levelset/shapes.hpp"
#include "liveset/swarm/swarm.hpp"

using namespace liveset;

namespace {

constexpr int kN = 48;
constexpr double kC = (kN - 1) / 2.0;  // 23.5
constexpr double kR = 15.0;
const Vec3d kCentre{kC, kC, kC};

SparseField sphere_field(double r = kR) {
    SparseField f(Lattice({kN, kN, kN}), 2);
    f.init_from_sdf(shapes::Sphere(kCentre, r));
    return f;
}

double off_surface(Vec3d x, double r = kR) { return std::abs(norm(x - kCentre) - r); }

// Normalised image: 1 inside radius `bright`, 0 outside, with a one-voxel linear ramp.
Grid<float> bright_ball(double bright) {
    Grid<float> g(Lattice({kN, kN, kN}));
    for (int z = 0; z < kN; ++z)
        for (int y = 0; y < kN; ++y)
            for (int x = 0; x < kN; ++x) {
                const double d = norm(Vec3d{double(x), double(y), double(z)} - kCentre) - bright;
                g({x, y, z}) = static_cast<float>(std::clamp(0.5 - d, 0.0, 1.0));
            }
    return g;
}

bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

}  // namespace

TEST(Swarm, RandomWalkersStayOnTheSurface) {
    const SparseField f = sphere_field();
    SwarmOptions o;
    o.agents = 200;
    o.attraction = 0.0;
    o.separation = 0.0;
    o.random_walk = 0.5;
    Swarm s(o);
    s.spawn(f, kCentre + Vec3d{kR, 0, 0}, 30.0);
    ASSERT_EQ(s.agents().size(), 200u);
    for (const Agent& a : s.agents()) EXPECT_LT(off_surface(a.position), 0.1);

    const Vec3d start = s.agents()[0].position;
    std::size_t reprojected = 0;
    for (int k = 0; k < 1000; ++k) {
        const StepReport r = s.move(f);
        ASSERT_EQ(r.on_surface, 200u) << "step " << k;
        reprojected += r.reprojected;
    }
    double worst = 0.0;
    std::size_t within = 0;
    for (const Agent& a : s.agents()) {
        const double d = off_surface(a.position);
        worst = std::max(worst, d);
        within += d < 0.1 ? 1 : 0;
    }
    std::cout << "[swarm] random walk 1000 steps: max |dist - r| " << worst << ", within 0.1: " << within
              << "/200, reprojections " << reprojected << "\n";
    EXPECT_LT(worst, 0.5);
    EXPECT_GE(within, 180u);
    EXPECT_EQ(reprojected, 0u);
    // They really walked: the first agent left its spawn point.
    EXPECT_GT(norm(s.agents()[0].position - start), 2.0);
}

TEST(Swarm, AttractionGathersAgentsAroundTheTargetWithoutCollapsing) {
    const SparseField f = sphere_field();
    SwarmOptions o;
    o.agents = 30;
    o.random_walk = 0.1;
    Swarm s(o);
    // Spawn on one side, target a quarter of the way round the sphere.
    s.spawn(f, kCentre + Vec3d{kR, 0, 0}, 6.0);
    const Vec3d target = kCentre + Vec3d{0, kR, 0};
    s.set_target(target);
    double initial = 0.0;
    for (const Agent& a : s.agents()) initial = std::max(initial, norm(a.position - target));
    for (int k = 0; k < 300; ++k) s.move(f);
    double worst = 0.0, mean = 0.0, min_pair = 1e9;
    for (std::size_t i = 0; i < s.agents().size(); ++i) {
        const Vec3d x = s.agents()[i].position;
        worst = std::max(worst, norm(x - target));
        mean += norm(x - target) / static_cast<double>(s.agents().size());
        EXPECT_LT(off_surface(x), 0.5);
        for (std::size_t j = 0; j < i; ++j) min_pair = std::min(min_pair, norm(x - s.agents()[j].position));
    }
    std::cout << "[swarm] attraction: start max dist " << initial << ", after 300 steps max " << worst << " mean "
              << mean << ", closest pair " << min_pair << "\n";
    EXPECT_GT(initial, 15.0);
    EXPECT_LT(worst, 3.5);
    EXPECT_GT(mean, 0.5);      // spread around the target, not collapsed on it
    EXPECT_GT(min_pair, 0.3);  // separation keeps them apart
}

TEST(Swarm, MotionIsTangentialWithoutPullBack) {
    const SparseField f = sphere_field();
    SwarmOptions o;
    o.agents = 50;
    o.pull_back = 0.0;
    o.attraction = 0.0;
    o.separation = 0.0;
    o.random_walk = 0.5;
    Swarm s(o);
    s.spawn(f, kCentre + Vec3d{0, 0, kR}, 30.0);
    const std::vector<Agent> before = s.agents();
    s.move(f);
    double mean_step = 0.0, worst_cos = 0.0;
    for (std::size_t i = 0; i < before.size(); ++i) {
        const Vec3d x = before[i].position;
        const Vec3d step = s.agents()[i].position - x;
        const Vec3d radial = (x - kCentre) / norm(x - kCentre);
        mean_step += norm(step) / static_cast<double>(before.size());
        ASSERT_GT(norm(step), 1e-3) << "agent " << i;  // the walk moved it
        EXPECT_LE(norm(step), o.max_step + 1e-12);
        worst_cos = std::max(worst_cos, std::abs(dot(step, radial)) / norm(step));
        // The interpolated normal matches the analytic one to about a degree.
        EXPECT_LT(std::abs(dot(step, radial)) / norm(step), 0.03) << "agent " << i;
        // And exactly orthogonal to the normal the swarm used.
        const Vec3d g = interpolated_gradient(f.phi(), x).cast<double>();
        EXPECT_LT(std::abs(dot(step, g / norm(g))), 1e-9) << "agent " << i;
    }
    std::cout << "[swarm] tangential: mean step " << mean_step << ", max |cos(step, radial)| " << worst_cos << "\n";
    EXPECT_GT(mean_step, 0.25);  // a random unit 0.5-vector keeps π/4·0.5 ≈ 0.39 on average
}

TEST(Swarm, AgentsOffTheBandAreNewtonProjectedBack) {
    // Spawned on r = 15, then the surface jumps to r = 16.5: every agent has |φ| ≈ 1.5 > 1.
    const SparseField f15 = sphere_field(kR);
    const SparseField f16 = sphere_field(kR + 1.5);
    SwarmOptions o;
    o.agents = 40;
    Swarm s(o);
    s.spawn(f15, kCentre + Vec3d{0, -kR, 0}, 30.0);
    const StepReport r = s.move(f16);
    EXPECT_EQ(r.reprojected, 40u);
    EXPECT_EQ(r.on_surface, 40u);
    for (const Agent& a : s.agents()) EXPECT_LT(off_surface(a.position, kR + 1.5), 0.1);
    // On r = 16 the agents have φ ≈ 0.5 < 1: no projection, the ε pull-back alone shrinks φ by ≈ ε·φ.
    const SparseField f16b = sphere_field(kR + 1.0);
    const StepReport r2 = s.move(f16b);
    EXPECT_EQ(r2.reprojected, 0u);
    for (const Agent& a : s.agents()) {
        EXPECT_LT(off_surface(a.position, kR + 1.0), 0.5 - 0.03);
        EXPECT_GT(off_surface(a.position, kR + 1.0), 0.5 - 0.1);
    }
}

// A one-voxel bubble inside the tissue (a noisy voxel a segmentation left out): φ peaks at its
// centre, where ∇φ = 0, so a plain Newton step from the lattice point jumps voxels away. The
// spawned agent must land on the bubble's own tiny surface, and the bubble can then be filled.
TEST(Swarm, AgentsLandOnAOneVoxelBubble) {
    Grid<std::uint8_t> mask(Lattice({kN, kN, kN}), 0);
    for (PointIndex i = 0; i < mask.size(); ++i) mask[i] = norm(mask.lattice().coord(i).cast<double>() - kCentre) <= 12.0;
    const Vec3i bubble{23, 23, 23};
    mask(bubble) = 0;
    SparseField f(mask.lattice(), 2);
    f.init_from_mask(mask);
    ASSERT_GT(f.phi()(bubble), 0.0f);
    ASSERT_EQ(f.status()(bubble), 0);  // the bubble is a zero-layer point of its own
    SwarmOptions o;
    o.agents = 1;
    Swarm s(o);
    s.spawn(f, bubble.cast<double>(), 3.0);
    const Vec3d x = s.agents()[0].position;
    EXPECT_LT(norm(x - bubble.cast<double>()), 1.0);
    EXPECT_LT(std::abs(trilinear(f.phi(), x)), 0.01);
}

TEST(Swarm, EditsExpandTowardsTheBrightRegionLocally) {
    SparseField f = sphere_field();
    const Grid<float> image = bright_ball(20.0);
    SwarmOptions o;
    o.agents = 20;
    o.act_probability = 1.0;
    o.attraction = 0.0;
    o.random_walk = 0.2;
    Swarm s(o);
    const Vec3d spot = kCentre + Vec3d{kR, 0, 0};
    s.spawn(f, spot, 5.0);
    const SparseField before = f;
    std::vector<Vec3d> visited;
    std::size_t changed = 0;
    for (int frame = 0; frame < 10; ++frame) {
        for (const Agent& a : s.agents()) visited.push_back(a.position);
        const auto edits = s.surface_edits(f, image);
        ASSERT_FALSE(edits.empty()) << "frame " << frame;
        for (std::size_t k = 0; k < edits.size(); ++k) {
            EXPECT_LT(edits[k].delta, 0.0f);  // expand only: outside is as bright as the population
            EXPECT_GE(edits[k].delta, -0.5f);
            if (k > 0) {
                EXPECT_LT(edits[k - 1].point, edits[k].point);  // sorted, merged
            }
        }
        changed += f.apply_edits(edits, RepairScope::kLocal).size();
        s.move(f);
    }
    ASSERT_NEAR(*s.intensity_mean(), 1.0, 1e-6);

    // The surface grew near the spot: the radial profile along +x moved outwards.
    const Vec3i probe{static_cast<int>(std::lround(spot.x)) + 1, static_cast<int>(std::lround(kC)),
                      static_cast<int>(std::lround(kC))};
    EXPECT_GT(before.phi()(probe), 0.0f);
    EXPECT_LT(f.phi()(probe), 0.0f);
    // Nothing changed away from every position an agent edited from.
    const double keep_out = o.edit_radius + f.layers() + 2.0;
    std::size_t far = 0, grown = 0;
    for (int z = 0; z < kN; ++z)
        for (int y = 0; y < kN; ++y)
            for (int x = 0; x < kN; ++x) {
                const Vec3i p{x, y, z};
                const Vec3d pd = p.cast<double>();
                double nearest = 1e9;
                for (const Vec3d& v : visited) nearest = std::min(nearest, norm(pd - v));
                if (nearest > keep_out) {
                    ++far;
                    ASSERT_EQ(before.phi()(p), f.phi()(p)) << p;
                    ASSERT_EQ(before.status()(p), f.status()(p)) << p;
                }
                if (f.phi()(p) < before.phi()(p)) ++grown;
            }
    std::cout << "[swarm] edits: " << changed << " point changes over 10 frames, " << grown
              << " points with lower phi, " << far << " far points unchanged\n";
    EXPECT_GT(far, 100000u);
    EXPECT_GT(grown, 20u);
}

TEST(Swarm, ContractsWhereTheInsideIsUnlikeThePopulation) {
    // Population statistics first learned on a bright sphere, then the image darkens inside the
    // surface: agents raise φ (contract).
    const SparseField f = sphere_field();
    SwarmOptions o;
    o.agents = 20;
    o.act_probability = 1.0;
    Swarm s(o);
    s.spawn(f, kCentre + Vec3d{kR, 0, 0}, 5.0);
    const Grid<float> bright = bright_ball(20.0);
    s.surface_edits(f, bright);  // μ = 1, σ = min_sigma
    // Image 0.5 on the surface, dark (0) inside, grey 0.5 outside: outside |0.5 − μ| > σ, inside far.
    Grid<float> odd(f.lattice(), 0.5f);
    for (int z = 0; z < kN; ++z)
        for (int y = 0; y < kN; ++y)
            for (int x = 0; x < kN; ++x)
                if (norm(Vec3d{double(x), double(y), double(z)} - kCentre) < kR - 1.0) odd({x, y, z}) = 0.0f;
    const auto edits = s.surface_edits(f, odd);
    ASSERT_FALSE(edits.empty());
    for (const ZeroLayerEdit& e : edits) EXPECT_GT(e.delta, 0.0f);
}

// The paper's speed experiment: acting agents raise or lower at random whatever the image says.
// On a flat image the intensity rule expands everywhere; the random rule does both, about evenly.
TEST(Swarm, RandomDecisionRaisesAndLowers) {
    const SparseField f = sphere_field();
    const Grid<float> flat(f.lattice(), 0.5f);
    SwarmOptions o;
    o.agents = 200;
    o.act_probability = 1.0;
    o.edit_radius = 0.5;  // each agent edits only the zero-layer points right under it
    for (EditDecision d : {EditDecision::kIntensity, EditDecision::kRandom}) {
        o.decision = d;
        Swarm s(o);
        s.spawn(f, kCentre + Vec3d{kR, 0, 0}, 30.0);
        for (int k = 0; k < 5; ++k) s.move(f);
        std::size_t raise = 0, lower = 0;
        for (const ZeroLayerEdit& e : s.surface_edits(f, flat)) (e.delta > 0 ? raise : lower) += 1;
        if (d == EditDecision::kIntensity) {
            EXPECT_EQ(raise, 0u);
            EXPECT_GT(lower, 50u);
        } else {
            EXPECT_GT(raise, 30u);
            EXPECT_GT(lower, 30u);
        }
    }
}

TEST(Swarm, BitIdenticalForOneAndTwoThreads) {
    auto run = [](int threads) {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        SparseField f = sphere_field();
        const Grid<float> image = bright_ball(18.0);
        SwarmOptions o;
        o.agents = 200;
        o.act_probability = 0.3;
        o.seed = 42;
        Swarm s(o);
        s.spawn(f, kCentre + Vec3d{0, kR, 0}, 40.0);
        s.set_target(kCentre + Vec3d{0, 0, kR});
        std::vector<ZeroLayerEdit> all;
        for (int k = 0; k < 60; ++k) {
            s.move(f);
            if (k % 5 == 0) {
                const auto e = s.surface_edits(f, image);
                all.insert(all.end(), e.begin(), e.end());
                f.apply_edits(e);
            }
        }
        return std::make_pair(s.agents(), all);
    };
    const auto [a1, e1] = run(1);
    const auto [a2, e2] = run(2);
    ASSERT_EQ(a1.size(), a2.size());
    for (std::size_t i = 0; i < a1.size(); ++i)
        for (int ax = 0; ax < 3; ++ax) {
            ASSERT_TRUE(same_bits(a1[i].position[ax], a2[i].position[ax])) << "agent " << i;
            ASSERT_TRUE(same_bits(a1[i].velocity[ax], a2[i].velocity[ax])) << "agent " << i;
        }
    ASSERT_EQ(e1.size(), e2.size());
    ASSERT_FALSE(e1.empty());
    for (std::size_t k = 0; k < e1.size(); ++k) {
        ASSERT_EQ(e1[k].point, e2[k].point);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(e1[k].delta), std::bit_cast<std::uint32_t>(e2[k].delta));
    }
}

TEST(Swarm, BadOptionsAndInputsThrow) {
    auto bad = [](auto change) {
        SwarmOptions o;
        change(o);
        EXPECT_THROW(validate(o), std::invalid_argument);
        EXPECT_THROW(Swarm{o}, std::invalid_argument);
    };
    EXPECT_NO_THROW(validate(SwarmOptions{}));
    bad([](SwarmOptions& o) { o.agents = 0; });
    bad([](SwarmOptions& o) { o.pull_back = -0.1; });
    bad([](SwarmOptions& o) { o.pull_back = 1.0; });
    bad([](SwarmOptions& o) { o.attraction = NAN; });
    bad([](SwarmOptions& o) { o.random_walk = -1; });
    bad([](SwarmOptions& o) { o.separation = INFINITY; });
    bad([](SwarmOptions& o) { o.separation_radius = 0; });
    bad([](SwarmOptions& o) { o.max_step = 0; });
    bad([](SwarmOptions& o) { o.max_step = 2; });
    bad([](SwarmOptions& o) { o.act_probability = 1.5; });
    bad([](SwarmOptions& o) { o.edit_radius = -1; });
    bad([](SwarmOptions& o) { o.edit_amount = 0.6; });
    bad([](SwarmOptions& o) { o.edit_amount = 0; });
    bad([](SwarmOptions& o) { o.min_sigma = 0; });
    bad([](SwarmOptions& o) { o.stats_smoothing = 0; });
    bad([](SwarmOptions& o) { o.sample_depth = -1; });
    bad([](SwarmOptions& o) { o.sample_depth = std::nan(""); });

    const SparseField f = sphere_field();
    Swarm s(SwarmOptions{});
    EXPECT_THROW(s.spawn(f, {0, 0, 0}, 2.0), std::invalid_argument);  // no zero-layer point near the corner
    EXPECT_THROW(s.spawn(f, kCentre, -1.0), std::invalid_argument);
    s.spawn(f, kCentre, 100.0);
    EXPECT_THROW(s.surface_edits(f, Grid<float>(Lattice({10, 10, 10}))), std::invalid_argument);
}

// With sample_depth the population samples the tissue inside the surface: on a sphere whose image
// is 1 inside and 0 outside (a one-voxel ramp at the surface), the mean is ≈ 0.5 at the agents and
// 1 two voxels inside.
TEST(Swarm, SampleDepthMovesThePopulationSamplesInside) {
    const SparseField f = sphere_field();
    const Grid<float> img = bright_ball(kR);
    for (double depth : {0.0, 2.0}) {
        SwarmOptions o;
        o.agents = 50;
        o.act_probability = 0.0;
        o.sample_depth = depth;
        Swarm s(o);
        s.spawn(f, kCentre + Vec3d{kR, 0, 0}, 30.0);
        s.surface_edits(f, img);
        ASSERT_TRUE(s.intensity_mean().has_value());
        if (depth == 0.0) {
            EXPECT_NEAR(*s.intensity_mean(), 0.5, 0.1);
        } else {
            EXPECT_NEAR(*s.intensity_mean(), 1.0, 1e-6);
        }
    }
}
