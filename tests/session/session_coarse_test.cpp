// Session's coarse start: from seeds on a fine grid the session's first steps run the coarse start
// one iteration each, and the session ends bit for bit where segment_image ends with its coarse start;
// a change during that run begins it again; undo goes back to the seeds.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <vector>

#include "liveset/levelset/invariants.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/session/session.hpp"
#include "liveset/session/session_runner.hpp"
#include "fine_shell.hpp"

namespace liveset {
namespace {

using liveset::testing::shell;
using liveset::testing::shell_seed;

SessionOptions shell_options(CoarseStart mode) {
    SessionOptions o;
    o.segmentation.step = segment_step();
    o.coarse_start = mode;
    return o;
}

std::unique_ptr<Session> shell_session(CoarseStart mode = CoarseStart::kAuto) {
    auto s = std::make_unique<Session>(shell().image, shell_options(mode), shell().roi);
    s->add_seed({shell_seed(), 2.0});
    return s;
}

SegmentOutcome shell_outcome(const Session& s, CoarseStart mode, std::vector<SeedBall> seeds) {
    SegmentRequest req;
    req.seeds = std::move(seeds);
    req.roi = &shell().roi;
    req.alpha = s.params().alpha;  // the session's fixed α (alpha_automatic off)
    req.loop.step = segment_step();
    req.coarse_start = mode;
    return segment_image(shell().image, req);
}

struct Bits {
    std::vector<std::uint32_t> phi;
    std::vector<std::int8_t> status;
    bool operator==(const Bits&) const = default;
};

Bits bits(const SparseField& f) {
    Bits b;
    for (float v : f.phi().values()) b.phi.push_back(std::bit_cast<std::uint32_t>(v));
    b.status.assign(f.status().values().begin(), f.status().values().end());
    return b;
}

// Steps until converged; the number of steps.
int converge(Session& s) {
    int steps = 0;
    while (!s.segment_status().converged && steps < 3000) {
        s.segment_step();
        ++steps;
    }
    return steps;
}

TEST(SessionCoarseStart, SegmentsExactlyAsLivesetSegmentsCoarseStart) {
    const std::unique_ptr<Session> s = shell_session();
    const Bits seeds = bits(s->field());
    const SegmentOutcome o = shell_outcome(*s, CoarseStart::kAuto, s->seeds());
    ASSERT_TRUE(o.coarse && o.coarse->used);
    ASSERT_EQ(o.coarse->result.reason, StopReason::kConverged);
    ASSERT_EQ(o.result.reason, StopReason::kConverged);
    EXPECT_EQ(s->params().mu, o.params.mu);

    // The coarse iterations leave φ alone, report no X and count no revision (nothing to redraw);
    // the last one upsamples.
    const std::uint64_t revision = s->revision();
    const std::size_t undo_depth = s->undo_depth();
    for (int k = 1; k < o.coarse->result.iterations; ++k) {
        const SessionUpdate u = s->segment_step();
        ASSERT_TRUE(u.changed.empty()) << k;
        ASSERT_EQ(s->revision(), revision) << k;
        ASSERT_TRUE(s->segment_status().coarse);
        ASSERT_EQ(s->segment_status().coarse_iterations, k);
        ASSERT_EQ(s->segment_status().iterations, 0);
    }
    EXPECT_EQ(bits(s->field()), seeds);
    s->end_action();  // a pause in the coarse run: an action that changed nothing is no undo step
    EXPECT_EQ(s->undo_depth(), undo_depth);
    const SessionUpdate last = s->segment_step();
    EXPECT_FALSE(last.changed.empty());
    EXPECT_EQ(s->segment_status().coarse_iterations, o.coarse->result.iterations);
    EXPECT_EQ(s->segment_status().coarse_inside, o.coarse->result.inside);
    EXPECT_FALSE(s->segment_status().converged);

    EXPECT_EQ(converge(*s), o.result.iterations);
    EXPECT_FALSE(s->segment_status().coarse);
    EXPECT_EQ(s->segment_status().iterations, o.result.iterations);
    EXPECT_TRUE(bits(s->field()) == bits(*o.field));
    EXPECT_EQ(canonical_triangles(s->mesher().merged()), canonical_triangles(marching_cubes_band(s->field().phi(), s->field().zero_layer())));

    // One action: undone, φ is the seeds' union again, and stepping again starts coarse again.
    s->end_action();
    s->undo();
    EXPECT_TRUE(bits(s->field()) == seeds);
    EXPECT_EQ(converge(*s), o.coarse->result.iterations + o.result.iterations);
    EXPECT_TRUE(bits(s->field()) == bits(*o.field));
}

TEST(SessionCoarseStart, AChangeDuringTheCoarseRunBeginsItAgain) {
    const std::unique_ptr<Session> s = shell_session();
    for (int k = 0; k < 5; ++k) s->segment_step();
    ASSERT_EQ(s->segment_status().coarse_iterations, 5);
    const double c = (liveset::testing::kShell - 1) / 2.0;
    const SeedBall second{{c - 31.0, c - 5.0, c + 5.0}, 2.0};  // the grey on the other side
    s->add_seed(second);
    s->segment_step();
    EXPECT_EQ(s->segment_status().coarse_iterations, 1);  // begun again, with both seeds
    const SegmentOutcome o = shell_outcome(*s, CoarseStart::kAuto, s->seeds());
    ASSERT_EQ(s->seeds().size(), 2u);
    EXPECT_EQ(converge(*s) + 1, o.coarse->result.iterations + o.result.iterations);
    EXPECT_TRUE(bits(s->field()) == bits(*o.field));
}

// The viewer's background run takes the same steps: the coarse ones and then the fine ones, with the
// hand-over between any two of them (the controller asks at every step here).
TEST(SessionCoarseStart, ABackgroundRunEndsWhereTheForegroundDoes) {
    const std::unique_ptr<Session> fg = shell_session();
    const int steps = converge(*fg);
    const std::unique_ptr<Session> bg = shell_session();
    SessionRunner runner(*bg);
    int coarse_seen = 0;
    runner.start(RunWork::kSegment, 0, [&](const SessionUpdate&, const RunState& st) {
        coarse_seen += st.status.coarse ? 1 : 0;
        return true;
    });
    while (!runner.wait_finished(5.0)) {
        runner.acquire();  // a frame: the worker parks between two steps
        EXPECT_TRUE(check_invariants(bg->field()).ok());
        runner.release();
    }
    const RunState st = runner.poll();
    EXPECT_TRUE(st.error.empty()) << st.error;
    EXPECT_EQ(st.steps, steps);
    EXPECT_EQ(coarse_seen, fg->segment_status().coarse_iterations);
    EXPECT_TRUE(st.status.converged);
    EXPECT_TRUE(bits(bg->field()) == bits(fg->field()));
    EXPECT_EQ(canonical_triangles(bg->mesher().merged()), canonical_triangles(fg->mesher().merged()));
}

// A recovery file keeps no "pristine" flag: a session recovered before its first step (φ the seeds'
// union, no iteration) starts coarse as the uninterrupted one would; one with an iteration does not.
TEST(SessionCoarseStart, ARecoveredSessionBeforeItsFirstStepStartsCoarse) {
    const std::unique_ptr<Session> s = shell_session();
    const int steps = converge(*s);
    const std::unique_ptr<Session> saved = shell_session();
    Session t(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    ASSERT_TRUE(t.load_recovered(saved->field().phi(), saved->field().status(), saved->marks()));
    EXPECT_EQ(converge(t), steps);
    EXPECT_TRUE(bits(t.field()) == bits(s->field()));

    // Two seeds (one re-initialised after a third was removed: init_from_seeds' bits) likewise.
    const double c = (liveset::testing::kShell - 1) / 2.0;
    saved->add_seed({{c - 31.0, c - 5.0, c + 5.0}, 2.0});
    saved->add_seed({{c, c - 31.0, c + 5.0}, 2.0});
    saved->remove_seed(2);
    Session two(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    two.load_recovered(saved->field().phi(), saved->field().status(), saved->marks());
    two.segment_step();
    EXPECT_TRUE(two.segment_status().coarse);

    SessionMarks stepped = saved->marks();
    stepped.iterations = 1;
    Session u(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    u.load_recovered(saved->field().phi(), saved->field().status(), stepped);
    u.segment_step();
    EXPECT_FALSE(u.segment_status().coarse);
    EXPECT_EQ(u.segment_status().iterations, 2);
}

// Seeds clicked one after another, overlapping (each united with φ in a box around it, not
// init_from_seeds): a session recovered before its first step still starts coarse, and ends bit for
// bit where the uninterrupted one does.
TEST(SessionCoarseStart, OverlappingSeedsClickedOneByOneAreRecognisedWhenRecovered) {
    const double c = (liveset::testing::kShell - 1) / 2.0;
    const auto clicked = [&] {
        std::unique_ptr<Session> s = shell_session();
        s->add_seed({shell_seed() + Vec3d{1.3, 0.6, -0.4}, 2.0});  // overlapping the first
        s->add_seed({{c - 31.0, c - 5.0, c + 5.0}, 2.5});
        s->add_seed({{c - 30.2, c - 4.1, c + 5.7}, 1.7});            // overlapping the third
        return s;
    };
    const std::unique_ptr<Session> s = clicked();
    const int steps = converge(*s);
    ASSERT_GT(s->segment_status().coarse_iterations, 0);
    const std::unique_ptr<Session> saved = clicked();
    Session t(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    ASSERT_TRUE(t.load_recovered(saved->field().phi(), saved->field().status(), saved->marks()));
    t.segment_step();
    EXPECT_TRUE(t.segment_status().coarse);
    EXPECT_EQ(converge(t) + 1, steps);
    EXPECT_TRUE(bits(t.field()) == bits(s->field()));
}

// A step taken with no surface said "vanished"; the seeds added since are a surface: the coarse
// steps say so, and a run does not stop after the first of them.
TEST(SessionCoarseStart, ASeedAfterAStepWithoutOneIsAFrontAgain) {
    Session s(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    s.segment_step();
    ASSERT_TRUE(s.segment_status().vanished);
    s.add_seed({shell_seed(), 2.0});
    s.segment_step();
    EXPECT_TRUE(s.segment_status().coarse);
    EXPECT_FALSE(s.segment_status().vanished);
    SessionRunner runner(s);
    runner.start(RunWork::kSegment, 10);
    runner.wait_finished(60'000.0);
    const RunState st = runner.poll();
    EXPECT_EQ(st.steps, 10);
    EXPECT_EQ(s.segment_status().coarse_iterations, 11);
}

// What the coarse run does not read - the swarm's target - does not begin it again.
TEST(SessionCoarseStart, ATargetSetDuringTheCoarseRunDoesNotBeginItAgain) {
    const std::unique_ptr<Session> s = shell_session();
    for (int k = 0; k < 4; ++k) s->segment_step();
    s->set_target(shell_seed() + Vec3d{2.0, 0.0, 0.0});
    s->segment_step();
    EXPECT_EQ(s->segment_status().coarse_iterations, 5);
}

// A brush stroke that moved the zero layer without changing a sign is no seeds' union: recovered,
// the session steps on the image's grid from the stroke, as the uninterrupted one does.
TEST(SessionCoarseStart, ARecoveredBrushStrokeIsNotTakenForTheSeeds) {
    const std::unique_ptr<Session> s = shell_session();
    const Vec3i c{static_cast<int>(shell_seed().x), static_cast<int>(shell_seed().y), static_cast<int>(shell_seed().z)};
    const SessionUpdate u = s->edit_box(c - Vec3i{4, 4, 4}, c + Vec3i{4, 4, 4}, [](Vec3i, float v) { return -0.5f * v; });  // halfway to 0
    ASSERT_FALSE(u.changed.empty());
    ASSERT_TRUE(!u.changed.sign_changes || u.changed.sign_changes->empty());
    Session t(shell().image, shell_options(CoarseStart::kAuto), shell().roi);
    t.load_recovered(s->field().phi(), s->field().status(), s->marks());
    s->segment_step();
    t.segment_step();
    EXPECT_FALSE(s->segment_status().coarse);
    EXPECT_FALSE(t.segment_status().coarse);
    EXPECT_TRUE(bits(t.field()) == bits(s->field()));
}

TEST(SessionCoarseStart, OffStepsTheImagesGridFromTheSeeds) {
    const std::unique_ptr<Session> s = shell_session(CoarseStart::kOff);
    const SessionUpdate u = s->segment_step();
    EXPECT_FALSE(u.changed.empty());
    EXPECT_FALSE(s->segment_status().coarse);
    EXPECT_EQ(s->segment_status().coarse_iterations, 0);
    EXPECT_EQ(s->segment_status().iterations, 1);
    // A changed step (here: the exact step) also ends a coarse run: it begins again under the new step.
    const std::unique_ptr<Session> t = shell_session(CoarseStart::kOn);
    for (int k = 0; k < 3; ++k) t->segment_step();
    t->set_step(StepOptions{});
    t->segment_step();
    EXPECT_EQ(t->segment_status().coarse_iterations, 1);
}

}  // namespace
}  // namespace liveset
