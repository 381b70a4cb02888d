// Session: segmenting from seeds gives bit for bit what `liveset segment` (segment_image) gives,
// the incremental mesh after any session update equals whole-volume marching cubes, the renderer
// feed (dirty fragments) keeps a mirror of the buffers exact, and undo/redo across seeds,
// segmentation and swarm actions restore φ, status and seeds exactly.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <map>
#include <vector>

#include "liveset/levelset/invariants.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/session/repair_presets.hpp"
#include "liveset/session/session.hpp"
#include "noisy_phantom.hpp"

namespace liveset {
namespace {

const Phantom& phantom64() {
    static const Phantom ph = [] {
        PhantomOptions o;
        o.size = 64;
        return make_phantom(o);
    }();
    return ph;
}

struct State {
    std::vector<std::uint32_t> phi;
    std::vector<std::int8_t> status;
    std::size_t seeds = 0;
    bool operator==(const State&) const = default;
};

State state_of(const Session& s) {
    State st;
    for (float v : s.field().phi().values()) st.phi.push_back(std::bit_cast<std::uint32_t>(v));
    st.status.assign(s.field().status().values().begin(), s.field().status().values().end());
    st.seeds = s.seeds().size();
    return st;
}

// A renderer stand-in: copies only the fragments the session reports dirty.
struct BufferMirror {
    std::map<FragmentId, Mesh> buffers;
    void sync(Session& s) {
        for (FragmentId f : s.take_dirty_fragments()) {
            const FragmentView v = s.mesher().fragment(f);
            buffers[f] = Mesh{{v.vertices.begin(), v.vertices.end()}, {v.indices.begin(), v.indices.end()}};
        }
    }
    void expect_matches(const Session& s) const {
        for (FragmentId f = 0; f < s.mesher().fragment_count(); ++f) {
            const FragmentView v = s.mesher().fragment(f);
            const auto it = buffers.find(f);
            const std::size_t n = it == buffers.end() ? 0 : it->second.vertices.size();
            ASSERT_EQ(n, v.vertices.size()) << "fragment " << f;
            if (n == 0) continue;
            ASSERT_TRUE(std::equal(v.indices.begin(), v.indices.end(), it->second.indices.begin(), it->second.indices.end()));
            for (std::size_t k = 0; k < n; ++k)
                for (int c = 0; c < 3; ++c) {
                    ASSERT_EQ(v.vertices[k].position[c], it->second.vertices[k].position[c]) << "fragment " << f;
                    ASSERT_EQ(v.vertices[k].normal[c], it->second.vertices[k].normal[c]) << "fragment " << f;
                }
        }
    }
};

void expect_mesh_is_whole_volume_mesh(const Session& s) {
    const Mesh whole = marching_cubes_band(s.field().phi(), s.field().zero_layer());
    ASSERT_GT(whole.triangle_count(), 0u);
    EXPECT_EQ(canonical_triangles(s.mesher().merged()), canonical_triangles(whole));
    FragmentMesher fresh(s.lattice(), s.mesher().fragment_size());
    fresh.full_rebuild(s.field().phi());
    for (FragmentId f = 0; f < fresh.fragment_count(); ++f) {
        const FragmentView a = fresh.fragment(f), b = s.mesher().fragment(f);
        ASSERT_EQ(a.vertices.size(), b.vertices.size()) << "fragment " << f;
        ASSERT_TRUE(std::equal(a.indices.begin(), a.indices.end(), b.indices.begin(), b.indices.end())) << "fragment " << f;
    }
}

SessionOptions options() {
    SessionOptions o;
    o.repair = demo_repair_options();
    return o;
}

// Steps the session until it converges: the same number of steps as `o`, and its φ and statuses
// bit for bit.
void expect_converges_as(Session& s, const SegmentOutcome& o) {
    ASSERT_EQ(o.result.reason, StopReason::kConverged);
    int steps = 0;
    while (!s.segment_status().converged && steps < 2000) {
        s.segment_step();
        ++steps;
    }
    EXPECT_EQ(steps, o.result.iterations);
    for (std::size_t i = 0; i < o.field->phi().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(s.field().phi()[p]), std::bit_cast<std::uint32_t>(o.field->phi()[p])) << i;
        ASSERT_EQ(s.field().status()[p], o.field->status()[p]) << i;
    }
}

TEST(Session, SegmentsFromSeedsExactlyAsLivesetSegment) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    SegmentRequest req;
    req.alpha = s.params().alpha;  // the session's fixed α (alpha_automatic off: SessionOptions' default)
    for (const Vec3i& c : ph.seeds) {
        req.seeds.push_back({c.cast<double>(), 2.0});
        s.add_seed({c.cast<double>(), 2.0});
    }
    const SegmentOutcome o = segment_image(ph.image, req);
    expect_converges_as(s, o);
    EXPECT_DOUBLE_EQ(s.params().mu, o.params.mu);
    EXPECT_DOUBLE_EQ(s.params().epsilon, o.params.epsilon);
    const Grid<std::uint8_t> mask = s.mask();
    EXPECT_TRUE(std::equal(mask.values().begin(), mask.values().end(), o.mask.values().begin(), o.mask.values().end()));
    expect_mesh_is_whole_volume_mesh(s);
}

// On a noisy scan the automatic choice blurs the image the threshold term reads: the session, with
// α automatic, still segments bit for bit as segment_image does without --alpha, and its
// speed_image() (the slice preview's) is that blur.
TEST(Session, SegmentsANoisyScanWithTheAutomaticBlurExactlyAsLivesetSegment) {
    const testing::NoisyAnisotropicPhantom noisy = testing::noisy_anisotropic_phantom(48);
    SessionOptions so = options();
    so.alpha_automatic = true;
    Session s(noisy.image, so);
    SegmentRequest req;
    for (const Vec3i& c : noisy.phantom.seeds) {
        req.seeds.push_back({c.cast<double>(), 2.0});
        s.add_seed({c.cast<double>(), 2.0});
    }
    const SegmentOutcome o = segment_image(noisy.image, req);
    ASSERT_GT(o.params.smooth_mm, 0.0);
    expect_converges_as(s, o);
    EXPECT_EQ(s.params().smooth_mm, o.params.smooth_mm);
    EXPECT_EQ(s.params().alpha, o.params.alpha);
    const Grid<float> blurred = gaussian_smooth(s.unit_image(), o.params.smooth_mm);
    EXPECT_TRUE(std::equal(blurred.values().begin(), blurred.values().end(), s.speed_image().values().begin()));
    // Without the blur (a given α and σ 0) the front ends elsewhere: the blur is what made the match.
    req.alpha = o.params.alpha;
    const SegmentOutcome plain = segment_image(noisy.image, req);
    EXPECT_FALSE(std::equal(plain.mask.values().begin(), plain.mask.values().end(), o.mask.values().begin()));
}

// A change of the blur alone is an undoable action of its own, and it changes the next steps.
TEST(Session, AChangeOfTheBlurAloneIsUndoneAndRedone) {
    const testing::NoisyAnisotropicPhantom noisy = testing::noisy_anisotropic_phantom(48);
    Session s(noisy.image, options());
    for (const Vec3i& c : noisy.phantom.seeds) s.add_seed({c.cast<double>(), 2.0});
    s.end_action();
    ThresholdParams p = s.params();
    ASSERT_EQ(p.smooth_mm, 0.0);
    p.smooth_mm = 0.7;
    s.set_params(p, s.window_from_seeds());
    s.end_action();
    EXPECT_EQ(s.params().smooth_mm, 0.7);
    ASSERT_TRUE(s.can_undo());
    s.undo();
    EXPECT_EQ(s.params().smooth_mm, 0.0);
    s.redo();
    EXPECT_EQ(s.params().smooth_mm, 0.7);
    for (int i = 0; i < 20; ++i) s.segment_step();
    const Grid<float> blurred = s.field().phi();
    s.undo();  // the steps
    s.undo();  // the blur
    EXPECT_EQ(s.params().smooth_mm, 0.0);
    for (int i = 0; i < 20; ++i) s.segment_step();
    EXPECT_FALSE(std::equal(blurred.values().begin(), blurred.values().end(), s.field().phi().values().begin()));
}

// With alpha_automatic the session's α is the one segment_image chooses for the same seeds (and the
// window they give), chosen again as seeds move the window; a given α turns it off, undo back on.
TEST(Session, AutomaticAlphaIsSegmentsForTheSeedsAndFollowsThem) {
    const testing::NoisyAnisotropicPhantom noisy = testing::noisy_anisotropic_phantom(48);
    const Phantom& ph = noisy.phantom;
    const Grid<float>& image = noisy.image;
    SessionOptions so = options();
    so.alpha_automatic = true;
    Session s(image, so);
    EXPECT_TRUE(s.alpha_automatic());
    SegmentRequest req;  // alpha unset: automatic
    const auto alpha_for = [&](std::size_t seeds) {
        req.seeds.clear();
        for (std::size_t k = 0; k < seeds; ++k) req.seeds.push_back({ph.seeds[k].cast<double>(), 2.0});
        req.loop.max_iterations = 1;
        return segment_image(image, req).alpha;
    };
    s.add_seed({ph.seeds[0].cast<double>(), 2.0});
    const AlphaChoice one = alpha_for(1);
    EXPECT_EQ(one.tissue_class, s.automatic_alpha_choice().tissue_class);
    EXPECT_EQ(s.params().alpha, one.alpha);
    EXPECT_EQ(s.params().smooth_mm, one.smooth_mm);  // noisy: blurred by half a voxel, as segment
    EXPECT_EQ(one.smooth_mm, 0.5 * static_cast<double>(image.lattice().spacing_float().x));
    EXPECT_GT(one.alpha, 0.0);
    EXPECT_LT(one.alpha, 0.1);
    for (std::size_t k = 1; k < ph.seeds.size(); ++k) s.add_seed({ph.seeds[k].cast<double>(), 2.0});
    EXPECT_EQ(s.params().alpha, alpha_for(ph.seeds.size()).alpha);  // chosen again for the window of all seeds
    const double automatic = s.params().alpha;
    s.end_action();

    ThresholdParams p = s.params();
    p.alpha = 0.3;
    s.set_params(p, true);  // a given α: fixed from now on
    s.end_action();
    EXPECT_FALSE(s.alpha_automatic());
    s.remove_seed(0);
    EXPECT_EQ(s.params().alpha, 0.3);
    s.end_action();
    s.undo();
    s.undo();  // back before the given α
    EXPECT_TRUE(s.alpha_automatic());
    EXPECT_EQ(s.params().alpha, automatic);

    // A window set by hand (or only µ of it): the class nearest its centre, as segment with --mu,
    // --epsilon; here not the seeds' class, and a different α.
    p = s.params();
    p.mu = 0.1;
    s.set_params(p, false, true);
    req.mu = 0.1;
    const AlphaChoice given = alpha_for(ph.seeds.size());  // the undo put the removed seed back
    EXPECT_NE(given.tissue_class, one.tissue_class);
    EXPECT_EQ(s.params().alpha, given.alpha);
    req.epsilon = s.params().epsilon;
    EXPECT_EQ(s.params().alpha, alpha_for(ph.seeds.size()).alpha);

    // No seeds (a level set loaded): no model, as segment --init-mask.
    Session bare(image, so);
    bare.load_mask(segment_image(image, req).mask);
    bare.segment_step();
    bare.end_action();
    EXPECT_EQ(bare.params().alpha, automatic_alpha(nullptr, bare.scale().to_raw(bare.params().mu), image.lattice().spacing_float()).alpha);
    ASSERT_TRUE(bare.can_undo());
    bare.undo();  // the choice was part of the step's action
    EXPECT_EQ(bare.params().alpha, so.params.alpha);
}

TEST(Session, UndoRedoRestoreEveryActionBitForBit) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    BufferMirror mirror;
    std::vector<State> states{state_of(s)};
    const auto act = [&](auto&& f) {
        f();
        s.end_action();
        mirror.sync(s);
        states.push_back(state_of(s));
    };
    act([&] { s.add_seed({ph.seeds[0].cast<double>(), 2.0}); });
    act([&] { s.add_seed({ph.seeds[1].cast<double>(), 2.0}); });
    act([&] { s.remove_seed(0); });  // pristine: re-initialised from the remaining seed
    act([&] { s.add_seed({ph.seeds[0].cast<double>(), 3.0}); });
    act([&] {
        for (int i = 0; i < 40; ++i) s.segment_step();
    });
    expect_mesh_is_whole_volume_mesh(s);
    act([&] {
        const auto t = s.nearest_surface_point(ph.seeds[0].cast<double>(), 40.0);
        ASSERT_TRUE(t.has_value());
        s.set_target(*t);
        for (int i = 0; i < 30; ++i) s.swarm_step();
    });
    expect_mesh_is_whole_volume_mesh(s);
    act([&] { s.add_seed({ph.seeds[2].cast<double>(), 2.0}); });  // grown: the ball is united
    act([&] {
        for (int i = 0; i < 10; ++i) s.segment_step();
    });
    mirror.expect_matches(s);
    ASSERT_EQ(s.undo_depth(), states.size() - 1);

    for (std::size_t a = states.size() - 1; a > 0; --a) {
        s.undo();
        mirror.sync(s);
        ASSERT_TRUE(state_of(s) == states[a - 1]) << "undo of action " << a;
        ASSERT_TRUE(check_invariants(s.field()).ok()) << check_invariants(s.field()).summary();
    }
    mirror.expect_matches(s);
    for (std::size_t a = 1; a < states.size(); ++a) {
        s.redo();
        mirror.sync(s);
        ASSERT_TRUE(state_of(s) == states[a]) << "redo of action " << a;
    }
    mirror.expect_matches(s);
    expect_mesh_is_whole_volume_mesh(s);
}

TEST(Session, RemovingASeedBeforeAnyStepReinitialisesFromTheOthers) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    s.add_seed({ph.seeds[0].cast<double>(), 2.0});
    s.add_seed({ph.seeds[1].cast<double>(), 2.5});
    s.remove_seed(0);
    SparseField want(ph.image.lattice(), 2);
    const std::vector<SeedBall> rest{{ph.seeds[1].cast<double>(), 2.5}};
    init_from_seeds(want, rest);
    for (std::size_t i = 0; i < want.phi().size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(s.field().phi()[static_cast<PointIndex>(i)]),
                  std::bit_cast<std::uint32_t>(want.phi()[static_cast<PointIndex>(i)]));
    EXPECT_EQ(s.seeds().size(), 1u);
    EXPECT_TRUE(s.seed_at(ph.seeds[1].cast<double>()).has_value());
    EXPECT_FALSE(s.seed_at(ph.seeds[0].cast<double>(), 0.5).has_value() &&
                 norm((ph.seeds[0] - ph.seeds[1]).cast<double>()) > 4.0);
    s.remove_seed(0);  // the last one: no front, every point far outside
    EXPECT_EQ(s.field().band_size(), 0u);
    const float far = static_cast<float>(s.field().layers() + 1);
    std::size_t not_far = 0;
    for (std::size_t i = 0; i < want.phi().size(); ++i)
        not_far += s.field().phi()[static_cast<PointIndex>(i)] != far || s.field().status()[static_cast<PointIndex>(i)] != far;
    EXPECT_EQ(not_far, 0u);
}

TEST(Session, KeepsTwentyActionsToUndo) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    s.add_seed({ph.seeds[0].cast<double>(), 2.0});
    std::vector<State> states{state_of(s)};
    for (int a = 0; a < 25; ++a) {
        // Alternate the two kinds so each run of steps is its own action.
        if (a % 2 == 0) {
            for (int i = 0; i < 3; ++i) s.segment_step();
        } else {
            ThresholdParams p = s.params();
            p.alpha = 0.1 + 0.01 * a;
            s.set_params(p, true);
        }
        states.push_back(state_of(s));
    }
    s.end_action();
    ASSERT_GE(s.undo_depth(), 20u);
    for (int a = 0; a < 20; ++a) {
        s.undo();
        ASSERT_TRUE(state_of(s) == states[states.size() - 2 - static_cast<std::size_t>(a)]) << a;
    }
}

TEST(Session, RejectsBadInputWithoutChangingAnything) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    EXPECT_THROW(s.add_seed({{-1, 0, 0}, 2.0}), std::invalid_argument);
    EXPECT_THROW(s.add_seed({{10, 10, 10}, 0.0}), std::invalid_argument);
    EXPECT_THROW(s.set_target({100, 0, 0}), std::invalid_argument);
    EXPECT_THROW(s.remove_seed(0), std::invalid_argument);
    ThresholdParams p;
    p.epsilon = -1;
    EXPECT_THROW(s.set_params(p, false), std::invalid_argument);
    EXPECT_FALSE(s.has_surface());
    EXPECT_FALSE(s.can_undo());
    EXPECT_TRUE(s.segment_step().changed.empty());  // nothing to evolve yet
    EXPECT_TRUE(s.swarm_step().changed.empty());    // no target yet
    Grid<std::uint8_t> wrong(Lattice({8, 8, 8}));
    EXPECT_THROW(s.load_mask(wrong), std::invalid_argument);
}

// With a ROI, a seed whose centre voxel lies outside it is refused by the session (the one edit
// path the CLI, Python and the viewer share) with a message naming the voxel; nothing changes.
// A seed on a ROI voxel next to it is accepted.
TEST(Session, RefusesASeedOutsideTheRoi) {
    const Phantom& ph = phantom64();
    Grid<std::uint8_t> roi(ph.image.lattice());
    const Vec3i d = roi.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x / 2; ++x) roi({x, y, z}) = 1;  // the ROI: the half with x < d.x / 2
    Session s(ph.image, options(), roi);
    // outside: no voxel of its ball (radius 2) in the ROI; astride: its centre outside, part of its ball in
    const Vec3d outside{d.x / 2.0 + 2.5, d.y / 2.0, d.z / 2.0}, inside{d.x / 2.0 - 1.0, d.y / 2.0, d.z / 2.0},
        astride{d.x / 2.0 + 1.0, d.y / 2.0, d.z / 2.0};
    try {
        s.add_seed({outside, 2.0});
        FAIL() << "a seed outside the ROI was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("outside the region of interest"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("(35, 32, 32)"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(s.seeds().empty());
    EXPECT_FALSE(s.has_surface());
    EXPECT_FALSE(s.can_undo());
    s.add_seed({inside, 2.0});
    EXPECT_EQ(s.seeds().size(), 1u);
    EXPECT_TRUE(s.has_surface());
    s.add_seed({astride, 2.0});  // clipped by the ROI, as `segment` clips it
    EXPECT_EQ(s.seeds().size(), 2u);
    // Without a ROI the same voxel is fine.
    Session free(ph.image, options());
    EXPECT_NO_THROW(free.add_seed({outside, 2.0}));
}

// clear_history forgets the actions (nothing to undo) and keeps φ, seeds and parameters; later
// actions undo back to that state, not to what came before it.
TEST(Session, ClearHistoryKeepsTheStateAndForgetsTheActions) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    s.add_seed({ph.seeds[0].cast<double>(), 2.0});
    ThresholdParams p = s.params();
    p.mu = 0.61;
    p.epsilon = 0.07;
    s.set_params(p, false);
    const State before = state_of(s);
    s.clear_history();
    EXPECT_FALSE(s.can_undo());
    EXPECT_TRUE(state_of(s) == before);
    EXPECT_EQ(s.params().mu, 0.61);
    s.add_seed({ph.seeds[1].cast<double>(), 2.0});
    s.undo();
    EXPECT_TRUE(state_of(s) == before);
    EXPECT_EQ(s.params().mu, 0.61);
    EXPECT_EQ(s.params().epsilon, 0.07);
    EXPECT_FALSE(s.can_undo());
}

TEST(Session, LoadedMaskStartsTheHistoryAfresh) {
    const Phantom& ph = phantom64();
    Session s(ph.image, options());
    s.add_seed({ph.seeds[0].cast<double>(), 2.0});
    s.end_action();
    s.load_mask(ph.truth);
    EXPECT_FALSE(s.can_undo());
    EXPECT_TRUE(s.has_surface());
    EXPECT_EQ(s.take_dirty_fragments().size(), s.mesher().fragment_count());
    expect_mesh_is_whole_volume_mesh(s);
}

}  // namespace
}  // namespace liveset

namespace liveset {
namespace {

// A phi image cannot tell every band point's layer: a point at exactly +-0.5 may be on L0 or on
// L+-1 (and a value of exactly +-1.5 on L+-1 or L+-2), so the far points next to them may come
// back as L+-2. The surface - signs, zero-layer values, the mesh - comes back exactly.
TEST(Session, ASavedPhiLoadsBackAsTheSameSurface) {
    const Phantom& ph = phantom64();
    Session a(ph.image, options());
    for (const Vec3i& c : ph.seeds) a.add_seed({c.cast<double>(), 2.0});
    for (int i = 0; i < 60; ++i) a.segment_step();
    Session b(ph.image, options());
    b.load_phi(a.field().phi());  // what `liveset view --phi` does with a saved phi
    ASSERT_TRUE(check_invariants(b.field()).ok()) << check_invariants(b.field()).summary();
    const Grid<std::uint8_t> ma = a.mask(), mb = b.mask();
    EXPECT_TRUE(std::equal(ma.values().begin(), ma.values().end(), mb.values().begin(), mb.values().end()));
    for (PointIndex p : a.field().zero_layer())
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a.field().phi()[p]), std::bit_cast<std::uint32_t>(b.field().phi()[p]));
    EXPECT_EQ(canonical_triangles(a.mesher().merged()), canonical_triangles(b.mesher().merged()));
}

// The brush sized to a hole: a disc of r² π t voxels through a shell t thick has radius r, and the
// brush reaches one voxel past it, within [3, max_range].
TEST(RepairPresets, HoleBrushIsTheHoleRadiusPlusOneVoxel) {
    constexpr double kPi = 3.14159265358979323846;
    EXPECT_NEAR(hole_brush_range(static_cast<std::size_t>(std::lround(25 * kPi * 3))), 6.0, 0.01);
    EXPECT_NEAR(hole_brush_range(static_cast<std::size_t>(std::lround(16 * kPi * 4)), 4.0), 5.0, 0.01);
    EXPECT_DOUBLE_EQ(hole_brush_range(1), 3.0);           // a tiny hole: the smallest brush
    EXPECT_DOUBLE_EQ(hole_brush_range(0), 3.0);
    EXPECT_DOUBLE_EQ(hole_brush_range(100000), 8.0);      // a huge one: the demo's widest brush
    EXPECT_DOUBLE_EQ(hole_brush_range(100000, 3.0, 12.0), 12.0);
    EXPECT_LT(hole_brush_range(200), hole_brush_range(400));
    EXPECT_THROW(hole_brush_range(10, 0.0), std::invalid_argument);
    EXPECT_THROW(hole_brush_range(10, std::nan("")), std::invalid_argument);
    EXPECT_THROW(hole_brush_range(10, 3.0, 2.0), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
