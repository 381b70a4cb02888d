// The viewer's background run (SessionRunner on a worker thread, frames taking its changes): a
// segmentation run equals the session's foreground steps (and so `liveset segment`) bit for bit at
// any hand-over pace; pause, a seed and undo during a run stop the worker first and leave a
// consistent session (pause: the same φ as the same number of foreground steps; undo: the state
// before the run); the 3D buffers end equal to the session's mesh; a coarse start's front is
// previewed while it runs (marching cubes of its φ). The session is read only
// between frames once the run stopped (the hand-over rule). No timing is asserted.
#include <gtest/gtest.h>

#include <bit>
#include <chrono>
#include <thread>

#include "liveset/levelset/invariants.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/render/headless_context.hpp"
#include "viewer.hpp"
#include "viewer_test_util.hpp"

#ifdef __SANITIZE_THREAD__
#include <tbb/global_control.h>
#endif

namespace liveset::viewer {
namespace {

using testing::phantom48;
using testing::seeded_session;

#ifdef __SANITIZE_THREAD__
// Under ThreadSanitizer (build-tsan, not CI): no oneTBB worker threads (an uninstrumented scheduler).
const tbb::global_control one_tbb_thread(tbb::global_control::max_allowed_parallelism, 1);
#endif

SessionOptions sleeping() {
    SessionOptions o;
    o.segmentation.step = sleeping_step();
    return o;
}

std::vector<std::uint32_t> bits(const Session& s) {
    std::vector<std::uint32_t> out;
    for (float v : s.field().phi().values()) out.push_back(std::bit_cast<std::uint32_t>(v));
    for (std::int8_t v : s.field().status().values()) out.push_back(static_cast<std::uint32_t>(v));
    return out;
}

// `view --coarse-start on`: the sleeping step after the coarse start, on the phantom's 1 mm grid too.
SessionOptions coarse_on() {
    SessionOptions o = sleeping();
    o.coarse_start = CoarseStart::kOn;
    return o;
}

ViewerConfig config(double handover_ms) {
    ViewerConfig c;
    c.headless = true;
    c.budget.handover_ms = handover_ms;
    return c;
}

// Frames as a window loop would give them (waiting for the hand-over between), `limit` at most,
// and with `min_steps` only until the frames have accounted that many of the run's steps (a run
// started by the first of them). Returns the steps the frames accounted.
int frames_while_running(Viewer& v, const render::Framebuffer& fb, int limit, int min_steps = 0) {
    int seen = 0;
    for (int n = 0; n < limit && v.segment_running() && (min_steps == 0 || seen < min_steps);) {
        if (!v.needs_frame()) {
            v.wait_for_frame(1000.0);
            continue;
        }
        v.frame(fb.id(), 640, 480, 1.0 / 60.0);
        seen += v.last_frame().segment_steps;
        ++n;
    }
    return seen;
}

// The first picture, a Run until it stops by itself (converged), and the picture after it.
void run_until_it_stops(Viewer& v, const render::Framebuffer& fb) {
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    v.set_segment_running(true);
    frames_while_running(v, fb, 100000);
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
}

// The foreground reference: the seeded session stepped on the caller's thread until it converges.
std::unique_ptr<Session> converged_in_the_foreground(const SessionOptions& o) {
    auto s = seeded_session(o);
    while (!s->segment_status().converged && s->segment_status().iterations < 5000) s->segment_step();
    return s;
}

// A fixed number of frames is not enough before a pause: on a loaded machine the worker may not
// have finished a step within a few 5 ms hand-overs, and a pause then closes an empty run, so an
// undo takes back the action before it.
void frames_until_steps(Viewer& v, const render::Framebuffer& fb, int steps) {
    ASSERT_GE(frames_while_running(v, fb, 100000, steps), steps) << "the run stopped before taking " << steps << " steps";
}

TEST(BackgroundRun, ASegmentationRunEqualsTheForegroundStepsAtAnyPace) {
    render::HeadlessContext context;
    const auto reference = converged_in_the_foreground(sleeping());
    for (const double pace : {1.0, 40.0}) {
        Viewer v(seeded_session(sleeping()), "phantom", config(pace));
        render::Framebuffer fb(640, 480);
        run_until_it_stops(v, fb);
        ASSERT_FALSE(v.segment_running());
        EXPECT_FALSE(v.background_active());
        const Session& s = *v.session();
        EXPECT_TRUE(s.segment_status().converged) << "pace " << pace;
        EXPECT_EQ(s.segment_status().iterations, reference->segment_status().iterations) << "pace " << pace;
        EXPECT_TRUE(bits(s) == bits(*reference)) << "pace " << pace;
        EXPECT_EQ(s.pending_mesh_points(), 0u);
        EXPECT_EQ(v.last_frame().triangles, s.mesher().triangle_count());  // the buffers hold the final mesh
        EXPECT_EQ(s.next_undo_label(), "segment");  // the run is one action
    }
}

// With the coarse start (`view --coarse-start on`): the run's first steps are the coarse start's,
// the surface jumps to its upsampled front at the step that ends it, and the run ends where the
// foreground steps end, bit for bit; the message counts both kinds of iteration.
TEST(BackgroundRun, ARunWithTheCoarseStartEqualsTheForegroundSteps) {
    render::HeadlessContext context;
    const SessionOptions o = coarse_on();
    const auto reference = converged_in_the_foreground(o);
    ASSERT_GT(reference->segment_status().coarse_iterations, 0);
    Viewer v(seeded_session(o), "phantom", config(5.0));
    render::Framebuffer fb(640, 480);
    run_until_it_stops(v, fb);
    ASSERT_FALSE(v.segment_running());
    const Session& s = *v.session();
    EXPECT_EQ(s.segment_status().coarse_iterations, reference->segment_status().coarse_iterations);
    EXPECT_EQ(s.segment_status().iterations, reference->segment_status().iterations);
    EXPECT_TRUE(bits(s) == bits(*reference));
    EXPECT_EQ(v.last_frame().triangles, s.mesher().triangle_count());
    EXPECT_NE(v.message().find("of the coarse start"), std::string::npos) << v.message();
}

// While the coarse start runs, φ is still the seeds: the viewer previews the coarse run's front.
// Stepped one coarse iteration a frame: the 3D pane's preview is marching cubes of the coarse φ on
// its grid after every frame, drawn where it lies on the image's grid (a pick on it lies on the
// coarse front at index 2c + 0.5), the axial pane fills more than the seeds, and a target cannot be
// set on it; a Run from there (background) ends as without the preview, which is then gone.
TEST(BackgroundRun, TheCoarseStartsFrontIsPreviewedWhileItRuns) {
    render::HeadlessContext context;
    const SessionOptions o = coarse_on();
    const auto reference = converged_in_the_foreground(o);
    ASSERT_GT(reference->segment_status().coarse_iterations, 8);
    auto session = seeded_session(o);
    const auto seeds_mesh = canonical_triangles(session->mesher().merged());
    Viewer v(std::move(session), "phantom", config(5.0));
    render::Framebuffer fb(640, 480);
    const auto matches_the_coarse_front = [&] {
        const SparseField* coarse = v.session()->coarse_field();
        if (coarse == nullptr || v.coarse_preview_mesher() == nullptr) return false;
        return canonical_triangles(v.coarse_preview_mesher()->merged()) ==
               canonical_triangles(marching_cubes_band(coarse->phi(), coarse->zero_layer()));
    };
    const auto reddish = [](const render::Image& img) {  // the label colour over grey
        std::size_t n = 0;
        for (std::size_t i = 0; i + 3 < img.rgba.size(); i += 4) n += img.rgba[i] > img.rgba[i + 1] + 25;
        return n;
    };
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    EXPECT_FALSE(v.coarse_preview_shown());  // no coarse run yet
    const std::size_t seeds_fill = reddish(v.capture_pane(Pane::kAxial, 240, 240));
    std::size_t last = 0;
    int changes = 0;
    for (int k = 0; k < 8; ++k) {
        v.segment_step();  // one coarse iteration
        v.frame(fb.id(), 640, 480, 1.0 / 60.0);
        ASSERT_TRUE(v.session()->segment_status().coarse) << k;
        ASSERT_TRUE(v.coarse_preview_shown()) << k;
        ASSERT_TRUE(matches_the_coarse_front()) << k;
        changes += k > 0 && v.coarse_preview_triangles() != last;
        last = v.coarse_preview_triangles();
    }
    EXPECT_GT(changes, 0);
    EXPECT_TRUE(canonical_triangles(v.session()->mesher().merged()) == seeds_mesh);  // the session's surface: the seeds
    EXPECT_GT(reddish(v.capture_pane(Pane::kAxial, 240, 240)), seeds_fill + seeds_fill / 4);

    const Rect r = v.pane_rect(Pane::kView3d);
    std::optional<render::Pick> pick;
    double px = 0.0, py = 0.0;
    for (int d = 0; d < 40 && !pick; d += 4) pick = v.click_3d(px = 0.5 * r.w + d, py = 0.5 * r.h + d, false);
    ASSERT_TRUE(pick.has_value()) << v.message();
    const Grid<float>& coarse = v.session()->coarse_field()->phi();
    const Vec3d at = (Vec3d{pick->index.x, pick->index.y, pick->index.z} - Vec3d{0.5, 0.5, 0.5}) / 2.0;  // coarse coordinates
    const Vec3i c{static_cast<int>(std::lround(at.x)), static_cast<int>(std::lround(at.y)), static_cast<int>(std::lround(at.z))};
    ASSERT_TRUE(coarse.lattice().contains(c.cast<double>())) << at;
    EXPECT_LT(std::abs(coarse(c)), 1.5f) << "the pick " << at << " (coarse) is off the coarse front";
    EXPECT_FALSE(v.click_3d(px, py, true).has_value());
    EXPECT_NE(v.message().find("coarse start is still running"), std::string::npos) << v.message();

    run_until_it_stops(v, fb);
    ASSERT_FALSE(v.segment_running());
    EXPECT_FALSE(v.coarse_preview_shown());
    EXPECT_EQ(v.coarse_preview_triangles(), 0u);
    EXPECT_EQ(v.session()->coarse_field(), nullptr);
    EXPECT_TRUE(bits(*v.session()) == bits(*reference));
    EXPECT_EQ(v.last_frame().triangles, v.session()->mesher().triangle_count());
}

TEST(BackgroundRun, PauseSeedAndUndoDuringARunStopTheWorkerFirst) {
    render::HeadlessContext context;
    Viewer v(seeded_session(sleeping()), "phantom", config(5.0));
    render::Framebuffer fb(640, 480);
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    const std::vector<std::uint32_t> before = bits(*v.session());
    v.set_segment_running(true);
    frames_until_steps(v, fb, 3);
    v.set_segment_running(false);  // pause: the worker is joined, the session is ours
    ASSERT_FALSE(v.background_active());
    const int k = v.session()->segment_status().iterations;
    auto reference = seeded_session(sleeping());
    for (int i = 0; i < k; ++i) reference->segment_step();
    EXPECT_TRUE(bits(*v.session()) == bits(*reference)) << k << " steps";
    v.undo();  // the run, one action
    EXPECT_TRUE(bits(*v.session()) == before);

    v.set_segment_running(true);  // again, a seed placed while it runs
    frames_while_running(v, fb, 2);
    const Vec3d extra = phantom48().seeds.front().cast<double>() + Vec3d{1.0, 1.0, 0.0};
    EXPECT_TRUE(v.add_seed(extra, 1.5)) << v.message();
    EXPECT_TRUE(v.segment_running());  // the run goes on after the seed, as in the foreground
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);  // starts the new worker; also counts the steps before the seed
    frames_until_steps(v, fb, 2);  // steps after the seed
    v.undo();  // pauses, then undoes the steps after the seed
    EXPECT_FALSE(v.segment_running());
    EXPECT_FALSE(v.background_active());
    EXPECT_TRUE(check_invariants(v.session()->field()).ok()) << check_invariants(v.session()->field()).summary();
    EXPECT_EQ(v.session()->next_undo_label(), "seed");
    v.frame(fb.id(), 640, 480, 1.0 / 60.0);
    EXPECT_EQ(v.last_frame().triangles, v.session()->mesher().triangle_count());
}

}  // namespace
}  // namespace liveset::viewer
