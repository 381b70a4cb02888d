// Camera fit: the smallest eye distance that keeps a box's corners inside the frustum.
#include "liveset/render/camera_fit.hpp"

#include <algorithm>
#include <cmath>

#include "liveset/render/surface_buffers.hpp"
#include "liveset/render/volume_transform.hpp"

namespace liveset::render {

Box surface_box(const FragmentMesher& mesher) {
    const glm::dmat4 m = index_to_world(mesher.lattice());
    Box b{glm::dvec3(1e300), glm::dvec3(-1e300)};
    bool any = false;
    for (FragmentId f = 0; f < mesher.fragment_count(); ++f)
        for (const Vertex& v : mesher.fragment(f).vertices) {
            const glm::dvec3 w(m * glm::dvec4(v.position[0], v.position[1], v.position[2], 1.0));
            b.lo = glm::min(b.lo, w);
            b.hi = glm::max(b.hi, w);
            any = true;
        }
    if (any) return b;
    const Vec3i d = mesher.lattice().dims();
    b = {glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 w(m * glm::dvec4((c & 1) ? d.x - 1 : 0, (c & 2) ? d.y - 1 : 0, (c & 4) ? d.z - 1 : 0, 1.0));
        b.lo = glm::min(b.lo, w);
        b.hi = glm::max(b.hi, w);
    }
    return b;
}

double zoom_to_fit(const OrbitCamera& camera, const Box& box, double aspect, double fill) {
    // Camera axes at the current pose: `back` from the centre towards the eye, `up`, `right`.
    const glm::dvec3 centre = camera.centre();
    const glm::dvec3 back = glm::normalize(camera.eye() - centre), up = glm::normalize(camera.up());
    const glm::dvec3 right = glm::cross(-back, up);
    const double tan_y = std::tan(glm::radians(OrbitCamera::kFieldOfViewDeg) / 2.0) * fill;
    const double tan_x = tan_y * std::max(aspect, 1e-3);
    // A point at (x, y, z) in those axes is seen at depth D − z from an eye at distance D: it is
    // inside when |y| ≤ tan_y (D − z) and |x| ≤ tan_x (D − z).
    double need = 1e-6;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 p((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z);
        const glm::dvec3 q = p - centre;
        const double x = glm::dot(q, right), y = glm::dot(q, up), z = glm::dot(q, back);
        need = std::max({need, z + std::abs(y) / tan_y, z + std::abs(x) / tan_x});
    }
    // distance() = distance at zoom 1 / zoom.
    const double at_one = camera.distance() * camera.pose().zoom;
    return std::clamp(at_one / need, 0.1, 50.0);
}

}  // namespace liveset::render
