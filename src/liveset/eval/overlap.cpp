// Volume-overlap scores (Dice, Jaccard, volume difference) and the shared lattice-compatibility check.
#include "liveset/eval/overlap.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

namespace liveset {

namespace {

std::string describe_dims(Vec3i d) {
    std::ostringstream os;
    os << d.x << "x" << d.y << "x" << d.z;
    return os.str();
}

std::string describe_placement(const Lattice& lat) {
    std::ostringstream os;
    os << "spacing " << lat.spacing() << " origin " << lat.origin() << " direction (";
    for (int i = 0; i < 9; ++i) os << (i ? "," : "") << lat.direction()[static_cast<std::size_t>(i)];
    os << ")";
    return os.str();
}

}  // namespace

void require_same_geometry(const Lattice& mask, const Lattice& truth, std::string_view caller, std::string_view mask_name,
                           std::string_view truth_name) {
    const std::string head = std::string(caller) + ": " + std::string(mask_name);
    if (!(mask.dims() == truth.dims())) {
        throw std::invalid_argument(head + " dims " + describe_dims(mask.dims()) + " differ from " + std::string(truth_name) +
                                    " dims " + describe_dims(truth.dims()));
    }
    if (!mask.same_geometry(truth, kEvalGeometryTolerance)) {
        throw std::invalid_argument(head + " geometry [" + describe_placement(mask) + "] differs from " +
                                    std::string(truth_name) + " geometry [" + describe_placement(truth) + "]");
    }
}

OverlapMetrics compare_overlap(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth) {
    require_same_geometry(mask.lattice(), truth.lattice(), "compare_overlap");

    OverlapMetrics m;
    const auto mv = mask.values();
    const auto tv = truth.values();
    for (std::size_t i = 0; i < mv.size(); ++i) {
        const bool a = mv[i] != 0;
        const bool b = tv[i] != 0;
        m.mask_voxels += a;
        m.truth_voxels += b;
        m.intersection_voxels += a && b;
    }

    const Vec3d s = mask.lattice().spacing();
    const double voxel_mm3 = s.x * s.y * s.z;
    m.mask_volume_mm3 = static_cast<double>(m.mask_voxels) * voxel_mm3;
    m.truth_volume_mm3 = static_cast<double>(m.truth_voxels) * voxel_mm3;

    const auto sum = static_cast<double>(m.mask_voxels + m.truth_voxels);
    const auto inter = static_cast<double>(m.intersection_voxels);
    const double uni = sum - inter;
    if (sum == 0) {
        // Both masks empty: they agree perfectly, by convention.
        m.dice = 1.0;
        m.jaccard = 1.0;
        m.volume_difference = 0.0;
    } else {
        m.dice = 2.0 * inter / sum;
        m.jaccard = inter / uni;
        m.volume_difference = m.truth_voxels == 0
                                  ? std::numeric_limits<double>::infinity()
                                  : (static_cast<double>(m.mask_voxels) - static_cast<double>(m.truth_voxels)) /
                                        static_cast<double>(m.truth_voxels);
    }
    return m;
}

}  // namespace liveset
