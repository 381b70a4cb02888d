// The 3D view's camera: orbits a centre (the volume's centre in LPS millimetres, moved by panning)
// at a distance, turntable-style around the superior axis (+z) so the head stays upright, with a
// perspective projection whose near/far planes hug the volume (precise depth for picking).
// yaw 0, pitch 0 looks from anterior with superior up; pitch +90 looks down from superior.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <string_view>

#include "liveset/render/volume_transform.hpp"

namespace liveset::render {

struct CameraPose {
    double yaw_deg = 0.0;     // around +z (superior), positive turns the camera towards the left (+x)
    double pitch_deg = 0.0;   // elevation in [-90, 90]
    double zoom = 1.0;        // > 1 moves closer
    glm::dvec3 pan{0.0};      // offset of the orbit centre from the volume centre, mm
};

class OrbitCamera {
public:
    static constexpr double kFieldOfViewDeg = 30.0;

    // Fits the camera to `bounds` and sets the home pose (reset() returns there).
    void frame(const Bounds& bounds, const CameraPose& home = default_pose());
    void reset() { pose_ = home_; }
    static CameraPose default_pose() { return {-30.0, 20.0, 1.0, glm::dvec3(0.0)}; }
    // Named views: "anterior", "posterior", "left", "right", "superior", "inferior", "default".
    // Returns false for an unknown name.
    static bool named_pose(std::string_view name, CameraPose& pose);

    const CameraPose& pose() const { return pose_; }
    void set_pose(const CameraPose& pose);

    // Mouse gestures in pixels of a viewport `height` pixels tall.
    void rotate(double dx_px, double dy_px);  // 0.4 degrees per pixel
    void pan(double dx_px, double dy_px, int height);
    void zoom(double factor);  // multiplies the zoom (clamped to [0.1, 50])

    glm::dvec3 centre() const { return bounds_.centre + pose_.pan; }
    double distance() const;
    glm::dvec3 eye() const;
    glm::dvec3 up() const;
    // Eye-space distances from the eye to the near and far side of the framed object's sphere.
    glm::dvec2 depth_range() const;
    glm::mat4 view() const;                    // world -> eye
    glm::mat4 projection(double aspect) const;  // eye -> clip

private:
    Bounds bounds_;
    CameraPose home_ = default_pose();
    CameraPose pose_ = default_pose();
};

}  // namespace liveset::render
