// A known hole for the hole-finder tests (session and viewer): the 64^3 phantom's grey-matter truth
// with a ball of radius 3.5 voxels drilled out where the sheet crosses the ray from the volume's
// centre towards -x (midway between its white-matter and its CSF side), so the drill joins the
// white matter to the outside through the sheet.
#pragma once

#include <cmath>
#include <cstdint>

#include "liveset/phantom/phantom.hpp"

namespace liveset::testing {

struct DrilledPhantom {
    Phantom phantom;
    Grid<std::uint8_t> mask;     // the truth minus the drill
    Grid<std::uint8_t> drilled;  // the truth voxels the drill removed
    std::size_t drilled_voxels = 0;
    Vec3i centre;                // the drill's centre (a grey-matter voxel)
};

inline DrilledPhantom make_drilled_phantom() {
    PhantomOptions o;
    o.size = 64;
    DrilledPhantom d{make_phantom(o), {}, {}, 0, {}};
    const Grid<std::uint8_t>& labels = d.phantom.labels;
    const Vec3i dims = labels.dims();
    int x = dims.x / 2;
    const int y = dims.y / 2, z = dims.z / 2;
    while (x > 0 && labels({x, y, z}) != kWhiteMatter) --x;  // into the white matter
    while (x > 0 && labels({x, y, z}) == kWhiteMatter) --x;  // to its edge: the sheet's inner side
    int out = x;
    while (out > 0 && labels({out, y, z}) == 2) --out;        // across the grey matter
    d.centre = {(x + out + 1) / 2, y, z};
    d.mask = d.phantom.truth;
    d.drilled = Grid<std::uint8_t>(labels.lattice(), 0);
    for (PointIndex i = 0; i < labels.size(); ++i) {
        const Vec3d p = labels.lattice().coord(i).cast<double>() - d.centre.cast<double>();
        if (d.phantom.truth[i] && dot(p, p) <= 3.5 * 3.5) {
            d.mask[i] = 0;
            d.drilled[i] = 1;
            ++d.drilled_voxels;
        }
    }
    return d;
}

inline const DrilledPhantom& drilled_phantom() {
    static const DrilledPhantom d = make_drilled_phantom();
    return d;
}

}  // namespace liveset::testing
