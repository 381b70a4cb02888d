// Framing the 3D view: with the zoom zoom_to_fit() gives, every corner of the box projects inside
// the view within the asked fill (brute force through the camera's own view and projection
// matrices), and at least one corner reaches it (the fit is tight, not just loose), for several
// directions, pans and aspect ratios (a tall pane is limited horizontally); the matrices are float,
// hence 1e-6.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "liveset/render/camera_fit.hpp"

namespace liveset {
namespace {

TEST(CameraFit, EveryCornerInsideAndOneAtTheFill) {
    const render::Box box{{-70.0, -100.0, -60.0}, {75.0, 90.0, 80.0}};  // a brain-sized box, off centre
    render::Bounds bounds;
    bounds.centre = 0.5 * (box.lo + box.hi);
    bounds.radius = 0.5 * glm::length(box.hi - box.lo);
    for (const render::CameraPose pose : {render::OrbitCamera::default_pose(), render::CameraPose{90.0, 0.0, 1.0, glm::dvec3(0.0)},
                                          render::CameraPose{180.0, 90.0, 1.0, glm::dvec3(0.0)},
                                          render::CameraPose{-30.0, 20.0, 1.0, glm::dvec3(10.0, -5.0, 3.0)}})
        for (const double aspect : {1.6, 1.0, 0.5}) {
            render::OrbitCamera camera;
            camera.frame(bounds, pose);
            const double fill = 0.9;
            render::CameraPose fitted = pose;
            fitted.zoom = render::zoom_to_fit(camera, box, aspect, fill);
            camera.set_pose(fitted);
            const glm::dmat4 m = glm::dmat4(camera.projection(aspect)) * glm::dmat4(camera.view());
            double most = 0.0;
            for (int c = 0; c < 8; ++c) {
                const glm::dvec4 p((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z, 1.0);
                const glm::dvec4 clip = m * p;
                ASSERT_GT(clip.w, 0.0);
                const double x = std::abs(clip.x / clip.w), y = std::abs(clip.y / clip.w);
                EXPECT_LE(x, fill + 1e-6) << pose.yaw_deg << " " << aspect;
                EXPECT_LE(y, fill + 1e-6) << pose.yaw_deg << " " << aspect;
                most = std::max({most, x, y});
            }
            EXPECT_NEAR(most, fill, 1e-6) << pose.yaw_deg << " " << aspect;
        }
}

}  // namespace
}  // namespace liveset
