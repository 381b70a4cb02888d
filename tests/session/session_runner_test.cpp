// SessionRunner: a background run takes the same steps as a caller stepping in the foreground and
// as `liveset segment` (segment_image), bit for bit, whatever the hand-over timing; a run stopped
// and continued equals an uninterrupted one of the same step count; the run is one undoable
// action; actions between a stop and a restart leave a consistent session; the deferred mesh, once
// flushed, is whole-volume marching cubes of φ.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <thread>
#include <vector>

#include "liveset/levelset/invariants.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/session/repair_presets.hpp"
#include "liveset/session/session_runner.hpp"

#ifdef __SANITIZE_THREAD__
#include <tbb/global_control.h>
#endif

namespace liveset {
namespace {

#ifdef __SANITIZE_THREAD__
// Under ThreadSanitizer (build-tsan, not CI): no oneTBB worker threads, whose uninstrumented
// scheduler TSan cannot see; the runner's own threads and locks stay as they are.
const tbb::global_control one_tbb_thread(tbb::global_control::max_allowed_parallelism, 1);
#endif

const Phantom& phantom48() {
    static const Phantom ph = [] {
        PhantomOptions o;
        o.size = 48;
        return make_phantom(o);
    }();
    return ph;
}

SessionOptions sleeping_options() {
    SessionOptions o;
    o.repair = demo_repair_options();
    o.segmentation.step = segment_step();  // what `liveset segment` takes
    return o;
}

std::unique_ptr<Session> seeded_session() {
    const Phantom& ph = phantom48();
    auto s = std::make_unique<Session>(ph.image, sleeping_options());
    for (const Vec3i& c : ph.seeds) s->add_seed({c.cast<double>(), 2.0});
    return s;
}

struct StepBits {
    std::vector<std::uint32_t> phi;
    std::vector<std::int8_t> status;
    int iterations = 0;
    bool operator==(const StepBits&) const = default;
};

StepBits step_bits(const Session& s) {
    StepBits out;
    for (float v : s.field().phi().values()) out.phi.push_back(std::bit_cast<std::uint32_t>(v));
    out.status.assign(s.field().status().values().begin(), s.field().status().values().end());
    out.iterations = s.segment_status().iterations;
    return out;
}

// The foreground reference: `steps` steps (0: until converged or vanished) on the caller's thread.
StepBits foreground(int steps) {
    auto s = seeded_session();
    for (int i = 0; steps == 0 ? !s->segment_status().converged && !s->segment_status().vanished && i < 5000 : i < steps; ++i)
        s->segment_step();
    return step_bits(*s);
}

void expect_mesh_is_marching_cubes(Session& s) {
    s.take_dirty_fragments();  // flushes the deferred X
    EXPECT_EQ(s.pending_mesh_points(), 0u);
    const Mesh whole = marching_cubes_band(s.field().phi(), s.field().zero_layer());
    ASSERT_GT(whole.triangle_count(), 0u);
    EXPECT_EQ(canonical_triangles(s.mesher().merged()), canonical_triangles(whole));
}

TEST(SessionRunner, ARunEqualsTheForegroundStepsAndLivesetSegment) {
    auto s = seeded_session();
    SessionRunner runner(*s);
    runner.start(RunWork::kSegment);
    ASSERT_TRUE(runner.wait_finished(120000.0));
    const RunState st = runner.poll();
    EXPECT_FALSE(st.active);
    EXPECT_TRUE(st.finished);
    EXPECT_TRUE(st.error.empty()) << st.error;
    EXPECT_TRUE(st.status.converged);
    EXPECT_FALSE(s->deferred_meshing());
    const StepBits fg = foreground(0);
    EXPECT_EQ(st.steps, fg.iterations);
    EXPECT_TRUE(step_bits(*s) == fg);

    SegmentRequest req;  // `liveset segment`: the sleeping step from the same seeds
    for (const Vec3i& c : phantom48().seeds) req.seeds.push_back({c.cast<double>(), 2.0});
    req.loop.step = segment_step();
    req.alpha = 0.1;  // the session's α (it does not choose one: docs/ARCHITECTURE.md)
    const SegmentOutcome cli = segment_image(phantom48().image, req);
    ASSERT_EQ(cli.result.reason, StopReason::kConverged);
    EXPECT_EQ(cli.result.iterations, st.steps);
    for (std::size_t i = 0; i < cli.field->phi().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(s->field().phi()[p]), std::bit_cast<std::uint32_t>(cli.field->phi()[p])) << i;
        ASSERT_EQ(s->field().status()[p], cli.field->status()[p]) << i;
    }
    expect_mesh_is_marching_cubes(*s);
}

// The controller takes the session every few ms (meshes, reads φ) while the worker steps: same φ.
TEST(SessionRunner, HandOversAtAnyTimeChangeNothing) {
    auto s = seeded_session();
    SessionRunner runner(*s);
    runner.start(RunWork::kSegment);
    std::size_t flushed = 0, handovers = 0;
    double checksum = 0.0;
    while (!runner.poll().finished && runner.active()) {
        runner.acquire();
        checksum += s->field().phi()[0];  // a read under the hand-over
        flushed += s->take_dirty_fragments().size();
        ++handovers;
        runner.release();
        std::this_thread::sleep_for(std::chrono::microseconds(300 * (handovers % 7)));
    }
    runner.poll();
    EXPECT_GT(handovers, 1u);
    EXPECT_GT(flushed, 0u);
    EXPECT_TRUE(std::isfinite(checksum));
    EXPECT_TRUE(step_bits(*s) == foreground(0));
    expect_mesh_is_marching_cubes(*s);
}

TEST(SessionRunner, StoppedAndContinuedEqualsUninterrupted) {
    constexpr int kSteps = 60;
    auto s = seeded_session();
    SessionRunner runner(*s);
    int done = 0;
    for (int round = 0; round < 4 && done < kSteps; ++round) {  // stopped at whatever step the timing gives
        runner.start(RunWork::kSegment, kSteps - done);
        std::this_thread::sleep_for(std::chrono::milliseconds(3 + 5 * round));
        if (round % 2) runner.acquire();  // a stop while holding the hand-over, too
        runner.stop();
        EXPECT_FALSE(runner.held());
        done += runner.state().steps;
        EXPECT_EQ(s->segment_status().iterations, done);
    }
    if (done < kSteps) {
        runner.start(RunWork::kSegment, kSteps - done);
        ASSERT_TRUE(runner.wait_finished(120000.0));
        done += runner.poll().steps;
    }
    ASSERT_EQ(done, kSteps);
    EXPECT_TRUE(step_bits(*s) == foreground(kSteps));
    EXPECT_TRUE(check_invariants(s->field()).ok()) << check_invariants(s->field()).summary();
}

TEST(SessionRunner, ARunIsOneUndoableAction) {
    auto s = seeded_session();
    s->end_action();
    const StepBits before = step_bits(*s);
    const std::size_t depth = s->undo_depth();
    SessionRunner runner(*s);
    runner.start(RunWork::kSegment, 40);
    ASSERT_TRUE(runner.wait_finished(120000.0));
    runner.poll();
    s->end_action();
    const StepBits after = step_bits(*s);
    EXPECT_EQ(after.iterations, 40);
    EXPECT_EQ(s->undo_depth(), depth + 1);
    EXPECT_EQ(s->next_undo_label(), "segment");
    s->undo();
    EXPECT_TRUE(step_bits(*s) == before);
    expect_mesh_is_marching_cubes(*s);
    s->redo();
    EXPECT_TRUE(step_bits(*s) == after);
    expect_mesh_is_marching_cubes(*s);
}

// What the viewer does on a seed during a run: stop, the action, start again. The session stays
// consistent and equals the same sequence taken in the foreground.
TEST(SessionRunner, ASeedBetweenRunsGivesTheForegroundSequence) {
    const Phantom& ph = phantom48();
    const SeedBall extra{ph.seeds.back().cast<double>() + Vec3d{1.0, 0.0, 0.0}, 1.5};
    auto s = seeded_session();
    SessionRunner runner(*s);
    runner.start(RunWork::kSegment, 25);
    ASSERT_TRUE(runner.wait_finished(120000.0));
    runner.stop();
    s->add_seed(extra);
    runner.start(RunWork::kSegment, 25);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    runner.acquire();
    runner.stop();  // mid-run, holding the hand-over
    const int second = runner.state().steps;
    EXPECT_TRUE(check_invariants(s->field()).ok()) << check_invariants(s->field()).summary();
    EXPECT_EQ(s->undo_depth(), ph.seeds.size() + 2);  // the seeds, segment, seed (the last run still open)
    auto ref = seeded_session();
    for (int i = 0; i < 25; ++i) ref->segment_step();
    ref->add_seed(extra);
    for (int i = 0; i < second; ++i) ref->segment_step();
    EXPECT_TRUE(step_bits(*s) == step_bits(*ref));
    expect_mesh_is_marching_cubes(*s);
}

TEST(SessionRunner, ASwarmRunEqualsForegroundSwarmSteps) {
    const auto grown = [] {
        auto s = seeded_session();
        for (int i = 0; i < 30; ++i) s->segment_step();
        const auto t = s->nearest_surface_point(phantom48().seeds[0].cast<double>(), 40.0);
        EXPECT_TRUE(t.has_value());
        s->set_target(*t);
        return s;
    };
    auto a = grown(), b = grown();
    SessionRunner runner(*a);
    runner.start(RunWork::kSwarm, 20);
    ASSERT_TRUE(runner.wait_finished(120000.0));
    EXPECT_EQ(runner.poll().steps, 20);
    for (int i = 0; i < 20; ++i) b->swarm_step();
    EXPECT_TRUE(step_bits(*a) == step_bits(*b));
    expect_mesh_is_marching_cubes(*a);
}

TEST(SessionRunner, AStepHookEndsTheRunAndAnErrorIsReported) {
    auto s = seeded_session();
    SessionRunner runner(*s);
    runner.start(RunWork::kSegment, 0, [](const SessionUpdate&, const RunState& st) { return st.steps < 7; });
    ASSERT_TRUE(runner.wait_finished(120000.0));
    EXPECT_EQ(runner.poll().steps, 7);
    runner.start(RunWork::kSwarm);  // no target: the run ends with one clear line
    ASSERT_TRUE(runner.wait_finished(120000.0));
    const RunState st = runner.poll();
    EXPECT_EQ(st.steps, 0);
    EXPECT_EQ(st.error, "the swarm has no target");
    EXPECT_EQ(s->segment_status().iterations, 7);
}

}  // namespace
}  // namespace liveset
