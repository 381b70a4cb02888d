// Orbit camera maths.
#include "liveset/render/orbit_camera.hpp"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace liveset::render {

namespace {

// Direction from the centre to the eye and the screen's up vector for a yaw/pitch.
void orbit_axes(double yaw_deg, double pitch_deg, glm::dvec3& to_eye, glm::dvec3& up) {
    const double yaw = glm::radians(yaw_deg), pitch = glm::radians(pitch_deg);
    const double cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
    // Rz(yaw) applied to (0, -cos p, sin p) and (0, sin p, cos p).
    to_eye = {sy * cp, -cy * cp, sp};
    up = {-sy * sp, cy * sp, cp};
}

}  // namespace

void OrbitCamera::frame(const Bounds& bounds, const CameraPose& home) {
    bounds_ = bounds;
    home_ = home;
    pose_ = home;
}

bool OrbitCamera::named_pose(std::string_view name, CameraPose& pose) {
    pose = CameraPose{};
    if (name == "default") pose = default_pose();
    else if (name == "anterior") pose.yaw_deg = 0.0;
    else if (name == "posterior") pose.yaw_deg = 180.0;
    else if (name == "left") pose.yaw_deg = 90.0;
    else if (name == "right") pose.yaw_deg = -90.0;
    else if (name == "superior") pose = {180.0, 90.0, 1.0, glm::dvec3(0.0)};  // anterior at the top
    else if (name == "inferior") pose = {0.0, -90.0, 1.0, glm::dvec3(0.0)};
    else return false;
    return true;
}

void OrbitCamera::set_pose(const CameraPose& pose) {
    pose_ = pose;
    pose_.pitch_deg = std::clamp(pose.pitch_deg, -90.0, 90.0);
    pose_.zoom = std::clamp(pose.zoom, 0.1, 50.0);
    pose_.yaw_deg = std::remainder(pose.yaw_deg, 360.0);
}

void OrbitCamera::rotate(double dx_px, double dy_px) {
    CameraPose p = pose_;
    p.yaw_deg -= 0.4 * dx_px;  // drag right: the object turns right (camera goes left)
    p.pitch_deg += 0.4 * dy_px;  // drag down: look from higher up
    set_pose(p);
}

void OrbitCamera::pan(double dx_px, double dy_px, int height) {
    glm::dvec3 to_eye, up;
    orbit_axes(pose_.yaw_deg, pose_.pitch_deg, to_eye, up);
    const glm::dvec3 right = glm::cross(-to_eye, up);
    // World size of one pixel at the centre's depth.
    const double mm_per_px = 2.0 * distance() * std::tan(glm::radians(kFieldOfViewDeg) / 2.0) / std::max(height, 1);
    pose_.pan += (-dx_px * right + dy_px * up) * mm_per_px;
}

void OrbitCamera::zoom(double factor) {
    if (!(factor > 0.0) || !std::isfinite(factor)) return;
    pose_.zoom = std::clamp(pose_.zoom * factor, 0.1, 50.0);
}

double OrbitCamera::distance() const {
    // The sphere around a bounding box is loose for a rounded object (a head fills about 60 % of
    // it): frame 0.7 of it. Clipping planes still use the whole sphere.
    const double fit = 0.7 * bounds_.radius / std::sin(glm::radians(kFieldOfViewDeg) / 2.0);
    return fit / pose_.zoom;
}

glm::dvec3 OrbitCamera::eye() const {
    glm::dvec3 to_eye, up;
    orbit_axes(pose_.yaw_deg, pose_.pitch_deg, to_eye, up);
    return centre() + distance() * to_eye;
}

glm::dvec3 OrbitCamera::up() const {
    glm::dvec3 to_eye, up;
    orbit_axes(pose_.yaw_deg, pose_.pitch_deg, to_eye, up);
    return up;
}

glm::dvec2 OrbitCamera::depth_range() const {
    const double d = glm::length(eye() - bounds_.centre);
    const double r = 0.75 * bounds_.radius;  // the object, not its box's corners
    return {std::max(d - r, 0.0), d + r};
}

glm::mat4 OrbitCamera::view() const { return glm::mat4(glm::lookAt(eye(), centre(), up())); }

glm::mat4 OrbitCamera::projection(double aspect) const {
    // Near and far planes around everything within the volume's sphere (plus any pan).
    const double d = distance();
    const double reach = bounds_.radius * 1.05 + glm::length(pose_.pan);
    const double near_plane = std::max(d - reach, d * 0.01);
    const double far_plane = d + reach;
    return glm::mat4(glm::perspective(glm::radians(kFieldOfViewDeg), std::max(aspect, 1e-3), near_plane, far_plane));
}

}  // namespace liveset::render
