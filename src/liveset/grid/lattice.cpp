// Lattice geometry: validation and index <-> world mapping.
#include "liveset/grid/lattice.hpp"

#include <cmath>
#include <sstream>

namespace liveset {

namespace {

double det3(const Mat3d& m) {
    return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
           m[2] * (m[3] * m[7] - m[4] * m[6]);
}

Mat3d inverse3(const Mat3d& m) {
    const double d = det3(m);
    Mat3d r{};
    r[0] = (m[4] * m[8] - m[5] * m[7]) / d;
    r[1] = (m[2] * m[7] - m[1] * m[8]) / d;
    r[2] = (m[1] * m[5] - m[2] * m[4]) / d;
    r[3] = (m[5] * m[6] - m[3] * m[8]) / d;
    r[4] = (m[0] * m[8] - m[2] * m[6]) / d;
    r[5] = (m[2] * m[3] - m[0] * m[5]) / d;
    r[6] = (m[3] * m[7] - m[4] * m[6]) / d;
    r[7] = (m[1] * m[6] - m[0] * m[7]) / d;
    r[8] = (m[0] * m[4] - m[1] * m[3]) / d;
    return r;
}

Vec3d mul(const Mat3d& m, Vec3d v) {
    return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
            m[6] * v.x + m[7] * v.y + m[8] * v.z};
}

}  // namespace

Lattice::Lattice(Vec3i dims, Vec3d spacing, Vec3d origin, Mat3d direction)
    : dims_(dims), spacing_(spacing), origin_(origin), direction_(direction) {
    if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) {
        std::ostringstream os;
        os << "lattice dimensions must be positive, got " << dims.x << "x" << dims.y << "x" << dims.z;
        throw std::invalid_argument(os.str());
    }
    const auto points = static_cast<std::uint64_t>(dims.x) * static_cast<std::uint64_t>(dims.y) *
                        static_cast<std::uint64_t>(dims.z);
    if (points > kMaxLatticePoints) {
        std::ostringstream os;
        os << "lattice " << dims.x << "x" << dims.y << "x" << dims.z << " has " << points
           << " points, more than the supported " << kMaxLatticePoints;
        throw std::invalid_argument(os.str());
    }
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(spacing[a]) || spacing[a] <= 0)
            throw std::invalid_argument("lattice spacing must be positive and finite");
        // The level set's curvature works with 1/spacing in float (speed.cpp): a size that float
        // cannot hold or invert (1e-46, 1e300) is no voxel size in mm anyway.
        if (spacing[a] < kMinSpacing || spacing[a] > kMaxSpacing) {
            std::ostringstream os;
            os << "lattice spacing " << spacing[a] << " is not a voxel size in mm (between " << kMinSpacing << " and "
               << kMaxSpacing << ")";
            throw std::invalid_argument(os.str());
        }
        if (!std::isfinite(origin[a])) throw std::invalid_argument("lattice origin must be finite");
    }
    for (double v : direction)
        if (!std::isfinite(v)) throw std::invalid_argument("lattice direction must be finite");
    if (std::abs(det3(direction)) < 1e-9)
        throw std::invalid_argument("lattice direction matrix is singular");
    Mat3d scaled = direction;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) scaled[3 * r + c] *= spacing[c];
    inverse_ = inverse3(scaled);
}

Vec3d Lattice::to_world(Vec3d ijk) const {
    return origin_ + mul(direction_, hadamard(ijk, spacing_));
}

Vec3d Lattice::to_index(Vec3d world) const { return mul(inverse_, world - origin_); }

Vec3d Lattice::direction_to_world(Vec3d index_dir) const {
    // A gradient transforms with the inverse transpose of the index->world Jacobian.
    const Mat3d& m = inverse_;
    const Vec3d w{m[0] * index_dir.x + m[3] * index_dir.y + m[6] * index_dir.z,
                  m[1] * index_dir.x + m[4] * index_dir.y + m[7] * index_dir.z,
                  m[2] * index_dir.x + m[5] * index_dir.y + m[8] * index_dir.z};
    const double n = norm(w);
    return n > 0 ? w / n : w;
}

bool Lattice::same_geometry(const Lattice& other, double tol) const {
    if (!(dims_ == other.dims_)) return false;
    for (int a = 0; a < 3; ++a) {
        if (std::abs(spacing_[a] - other.spacing_[a]) > tol) return false;
        if (std::abs(origin_[a] - other.origin_[a]) > tol) return false;
    }
    for (int i = 0; i < 9; ++i)
        if (std::abs(direction_[i] - other.direction_[i]) > tol) return false;
    return true;
}

std::string Lattice::describe() const {
    std::ostringstream os;
    os << dims_.x << "x" << dims_.y << "x" << dims_.z << ", spacing " << spacing_.x << "x" << spacing_.y
       << "x" << spacing_.z;
    return os.str();
}

}  // namespace liveset
