// The viewer's frame budget: its decisions (steps per frame, redraw pacing, level of detail) from
// given costs, compared with counts worked out by hand; a segmentation run in the viewer under
// any budget equals the Session's (and so `liveset segment`'s) bit for bit after the same number
// of steps; the coarse level of detail is drawn while a drag is held and the full surface after,
// both showing the same silhouette. No timing is asserted.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "frame_budget.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/render/headless_context.hpp"
#include "viewer.hpp"
#include "viewer_test_util.hpp"

namespace liveset::viewer {
namespace {

using testing::phantom48;
using testing::seeded_session;

// Steps one frame takes when every step costs `step` ms and the upload `upload` ms.
int steps_in_frame(FrameBudget& b, double step, double upload) {
    int n = 0;
    double elapsed = 0.0;
    while (b.another_step(n, elapsed) && n < 10000) {
        b.record_step(step);
        elapsed += step;
        ++n;
    }
    b.record_upload(upload);
    return n;
}

TEST(FrameBudget, TakesAsManyStepsAsFitWithTheUploadAndAlwaysOne) {
    FrameBudgetOptions o;
    o.frame_ms = 30.0;
    FrameBudget b(o);
    // Constant costs: the first frame knows no costs yet, later frames fit floor((30 - upload) / step).
    steps_in_frame(b, 4.0, 2.0);
    for (int f = 0; f < 3; ++f) EXPECT_EQ(steps_in_frame(b, 4.0, 2.0), 7);  // 7 x 4 + 2 = 30
    FrameBudget slow(o);
    for (int f = 0; f < 3; ++f) EXPECT_EQ(steps_in_frame(slow, 45.0, 1.0), 1);  // over budget: still one step
    FrameBudget cheap(o);
    steps_in_frame(cheap, 0.5, 0.0);
    EXPECT_EQ(steps_in_frame(cheap, 0.5, 0.0), 60);
}

TEST(FrameBudget, FollowsAChangeOfStepCost) {
    FrameBudget b;
    for (int f = 0; f < 3; ++f) steps_in_frame(b, 2.0, 0.0);
    EXPECT_EQ(steps_in_frame(b, 2.0, 0.0), 15);
    // The surface grew: steps cost 5 ms now; within a few frames the count is 6.
    for (int f = 0; f < 6; ++f) steps_in_frame(b, 5.0, 0.0);
    EXPECT_EQ(steps_in_frame(b, 5.0, 0.0), 6);
}

TEST(FrameBudget, PacesRedrawsToTheDrawShare) {
    FrameBudgetOptions o;
    o.draw_share = 0.2;
    FrameBudget b(o);
    EXPECT_TRUE(b.redraw_due(0.0));  // never redrawn yet
    b.record_redraw(1000.0, 100.0);  // cost 100 ms: next one after 100 x (1 / 0.2 - 1) = 400 ms
    EXPECT_FALSE(b.redraw_due(1399.0));
    EXPECT_TRUE(b.redraw_due(1400.0));
    b.record_redraw(1400.0, 1.0);  // a cheap redraw (a GPU): due again 4 ms later
    EXPECT_TRUE(b.redraw_due(1404.0));
}

TEST(FrameBudget, CoarseWhileBusyOrRecentlyTouchedAndOnlyWhenFullDrawsAreSlow) {
    FrameBudgetOptions o;
    o.still_ms = 300.0;
    o.lod_above_ms = 50.0;
    FrameBudget b(o);
    EXPECT_FALSE(b.coarse(0.0, true));  // no full draw measured yet
    b.record_full_draw(20.0);           // a GPU: never coarse
    EXPECT_FALSE(b.coarse(0.0, true));
    FrameBudget slow(o);
    slow.record_full_draw(400.0);  // llvmpipe and a whole brain
    EXPECT_FALSE(slow.coarse(0.0, false));
    EXPECT_TRUE(slow.coarse(0.0, true));
    slow.record_input(100.0);
    EXPECT_TRUE(slow.coarse(399.0, false));
    EXPECT_FALSE(slow.coarse(400.0, false));
}

TEST(FrameBudget, RefusesBadOptions) {
    FrameBudgetOptions o;
    o.frame_ms = 0.0;
    EXPECT_THROW(FrameBudget{o}, std::invalid_argument);
    o = {};
    o.draw_share = 1.5;
    EXPECT_THROW(FrameBudget{o}, std::invalid_argument);
    o = {};
    o.still_ms = std::nan("");
    EXPECT_THROW(FrameBudget{o}, std::invalid_argument);
    o = {};
    o.lod_factor = 1;
    EXPECT_THROW(FrameBudget{o}, std::invalid_argument);
}

bool same_phi(const Session& a, const Session& b) {
    const auto& pa = a.field().phi().values();
    const auto& pb = b.field().phi().values();
    if (pa.size() != pb.size()) return false;
    for (std::size_t i = 0; i < pa.size(); ++i)
        if (std::bit_cast<std::uint32_t>(pa[i]) != std::bit_cast<std::uint32_t>(pb[i])) return false;
    return std::equal(a.field().status().values().begin(), a.field().status().values().end(), b.field().status().values().begin());
}

// Runs the segmentation in a viewer with `frame_ms`, checking after every frame that φ is the
// Session's after the same number of steps; returns the iterations at convergence.
int run_in_viewer(double frame_ms) {
    ViewerConfig c;
    c.headless = true;
    c.budget.frame_ms = frame_ms;
    c.budget.background = false;  // steps in frames (background_run_test.cpp: on a worker)
    Viewer v(seeded_session(SessionOptions{}), "phantom", c);
    auto reference = seeded_session(SessionOptions{});
    render::Framebuffer window(640, 480);
    v.set_segment_running(true);
    int frames = 0;
    while (v.segment_running() && frames < 5000) {
        v.frame(window.id(), 640, 480, 1.0 / 60.0);
        ++frames;
        const int k = v.session()->segment_status().iterations;
        while (reference->segment_status().iterations < k) reference->segment_step();
        EXPECT_TRUE(same_phi(*v.session(), *reference)) << "after " << k << " steps, frame " << frames;
        EXPECT_GE(v.last_frame().segment_steps, v.segment_running() ? 1 : 0);
    }
    EXPECT_TRUE(v.session()->segment_status().converged);
    EXPECT_TRUE(reference->segment_status().converged);  // converged at the same step
    return v.session()->segment_status().iterations;
}

TEST(ViewerBudget, SegmentationInFramesEqualsTheSessionBitForBitWhateverTheBudget) {
    render::HeadlessContext context;
    const int tight = run_in_viewer(0.001);  // one step per frame
    const int wide = run_in_viewer(1000.0);  // many steps per frame
    EXPECT_EQ(tight, wide);
    EXPECT_GT(tight, 5);
}

// The 3D pane's pixels that are not background.
std::vector<bool> silhouette(const render::Image& img, const Rect& r) {
    std::vector<bool> s;
    for (int y = r.y; y < r.y + r.h; ++y)
        for (int x = r.x; x < r.x + r.w; ++x) {
            const std::uint8_t* p = &img.rgba[4 * (static_cast<std::size_t>(y) * img.width + x)];
            s.push_back(std::abs(p[0] - 26) + std::abs(p[1] - 28) + std::abs(p[2] - 33) > 12);  // SceneStyle::background
        }
    return s;
}

TEST(ViewerBudget, CoarseSurfaceWhileDraggingFullSurfaceOnceReleasedSameSilhouette) {
    render::HeadlessContext context;
    ViewerConfig c;
    c.headless = true;
    c.budget.lod_above_ms = 0.0;     // the phantom's surface draws fast: force the level of detail
    c.budget.lod_factor = 2;
    c.budget.still_ms = 0.0;         // full quality as soon as nothing is held
    auto s = seeded_session(SessionOptions{});
    for (int i = 0; i < 30; ++i) s->segment_step();
    s->end_action();
    Viewer v(std::move(s), "phantom", c);
    v.set_maximised(Pane::kView3d);
    const int w = 800, h = 600;
    v.set_window_size(w, h);
    const Rect r = v.pane_rect(Pane::kView3d);
    const render::Image full = v.capture_window(w, h);
    EXPECT_FALSE(v.view3d_coarse());
    InputEvent press;
    press.type = InputEvent::Type::kPress;
    press.x = r.x + r.w / 2.0;
    press.y = r.y + r.h / 2.0;
    v.push_event(press);
    v.camera_changed();
    const render::Image coarse = v.capture_window(w, h);
    EXPECT_TRUE(v.view3d_coarse());
    InputEvent release = press;
    release.type = InputEvent::Type::kRelease;
    v.push_event(release);
    const render::Image after = v.capture_window(w, h);
    EXPECT_FALSE(v.view3d_coarse());
    const auto a = silhouette(full, r), b = silhouette(coarse, r), d = silhouette(after, r);
    std::size_t inside = 0, differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        inside += a[i];
        differ += a[i] != b[i];
    }
    ASSERT_GT(inside, a.size() / 20);  // the surface fills a good part of the pane
    // The coarse surface covers the same pixels (same size and place; a wrong scale or offset moves
    // most of them) but for the thinnest folds, which half the resolution rounds off (5.5 % here).
    EXPECT_LT(differ, inside / 10);
    EXPECT_EQ(a, d);                   // full quality again once released
    EXPECT_NE(full.rgba, coarse.rgba); // and the drag did draw another (coarse) surface
}

}  // namespace
}  // namespace liveset::viewer
