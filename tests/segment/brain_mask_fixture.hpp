// Shared by the brain-mask tests (brain_mask_test.cpp, brain_mask_neck_test.cpp): BrainWeb read
// once, a 2 mm version of a grid, BrainWeb with a neck below it, and the mask against BrainWeb's labels.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/morphology.hpp"

namespace liveset::bm_test {

using Mask = Grid<std::uint8_t>;

struct BrainWeb {
    Grid<float> t1;
    Mask labels, brain_mask;  // brain_mask.nii.gz: the mask the skull-stripped variant is cut with
};

inline const BrainWeb& brainweb() {
    static const BrainWeb data = [] {
        const std::filesystem::path dir = std::filesystem::path(LIVESET_DATA_DIR) / "brainweb";
        if (!std::filesystem::exists(dir / "t1.mha")) throw std::runtime_error("BrainWeb data not found in " + dir.string());
        return BrainWeb{read_image((dir / "t1.mha").string()), read_label_image((dir / "labels_crisp.nii.gz").string()),
                        read_label_image((dir / "brain_mask.nii.gz").string())};
    }();
    return data;
}

inline bool brain_label(int l) { return l == 1 || l == 2 || l == 3 || l == 8; }
inline bool extracranial_label(int l) { return l == 4 || l == 5 || l == 6 || l == 9; }  // fat, muscle, skin, connective

// Every other voxel along each axis: a 2 mm version of a 1 mm grid (same origin and direction).
template <class T>
Grid<T> every_other(const Grid<T>& g) {
    const Lattice& l = g.lattice();
    const Vec3i d{(l.dims().x + 1) / 2, (l.dims().y + 1) / 2, (l.dims().z + 1) / 2};
    Grid<T> out(Lattice(d, l.spacing() * 2.0, l.origin(), l.direction()));
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) out({x, y, z}) = g({2 * x, 2 * y, 2 * z});
    return out;
}

struct TruthCheck {
    double dice = 0, gm = 0, wm = 0, extracranial = 0, leak = 0;
};

// The mask against BrainWeb's brain tissue (labels 1, 2, 3, 8). `leak`: non-brain voxels inside the
// mask whose intensity lies in grey matter's 1st–99th percentile (where a grey-matter front could
// grow), as a fraction of the grey-matter volume.
inline TruthCheck check_against_truth(const Mask& mask, const Mask& labels, const Grid<float>& image) {
    std::vector<float> gm_values;
    for (std::size_t i = 0; i < labels.size(); ++i)
        if (labels[static_cast<PointIndex>(i)] == 2) gm_values.push_back(image[static_cast<PointIndex>(i)]);
    std::sort(gm_values.begin(), gm_values.end());
    const float lo = gm_values[gm_values.size() / 100], hi = gm_values[gm_values.size() * 99 / 100];
    std::size_t m = 0, t = 0, both = 0, gm = 0, gm_in = 0, wm = 0, wm_in = 0, ex = 0, ex_in = 0, leak = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        const int l = labels[p];
        const bool in = mask[p] != 0;
        m += in;
        t += brain_label(l);
        both += in && brain_label(l);
        gm += l == 2;
        gm_in += l == 2 && in;
        wm += l == 3;
        wm_in += l == 3 && in;
        ex += extracranial_label(l);
        ex_in += extracranial_label(l) && in;
        leak += in && !brain_label(l) && image[p] >= lo && image[p] <= hi;
    }
    return {2.0 * double(both) / double(m + t), double(gm_in) / double(gm), double(wm_in) / double(wm),
            double(ex_in) / double(ex), double(leak) / double(gm)};
}

// BrainWeb (whose field of view ends at the skull base) with `depth` mm of neck below it, as a
// scan down to the shoulders has: its lowest ten slices cycled inside the head's cross-section of
// the lowest slice narrowed by 1 mm every 10 mm (muscle, fat, skin, connective tissue; no brain).
// The lattice grows downwards: every BrainWeb voxel keeps its world position. `labels` likewise
// (0 in the neck).
inline Grid<float> with_neck(const Grid<float>& t1, int depth, Mask* labels, const Mask& bw_labels) {
    const Lattice& l = t1.lattice();
    const Vec3i d = l.dims();
    const Lattice ext({d.x, d.y, d.z + depth}, l.spacing(), l.to_world({0.0, 0.0, -static_cast<double>(depth)}), l.direction());
    Grid<float> out(ext, 0.0f);
    *labels = Mask(ext, 0);
    // The lowest slice's head, its holes filled (a flood of the outside from the slice's edge).
    Mask section(Lattice({d.x, d.y, 1}, l.spacing()), 1);
    std::vector<Vec3i> todo;
    for (int y = 0; y < d.y; ++y)
        for (int x = 0; x < d.x; ++x)
            if ((x == 0 || y == 0 || x == d.x - 1 || y == d.y - 1) && t1({x, y, 0}) <= 20.0f) todo.push_back({x, y, 0});
    while (!todo.empty()) {
        const Vec3i p = todo.back();
        todo.pop_back();
        if (p.x < 0 || p.y < 0 || p.x >= d.x || p.y >= d.y || section(p) == 0 || t1(p) > 20.0f) continue;
        section(p) = 0;
        for (const Vec3i step : {Vec3i{1, 0, 0}, Vec3i{-1, 0, 0}, Vec3i{0, 1, 0}, Vec3i{0, -1, 0}}) todo.push_back(p + step);
    }
    for (int k = 0; k < depth; ++k) {  // k + 1 mm below the lowest slice
        const Mask neck = erode_mm(section, 1.0 + k / 10);
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (neck({x, y, 0})) out({x, y, depth - 1 - k}) = t1({x, y, 9 - k % 10});
    }
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                out({x, y, z + depth}) = t1({x, y, z});
                (*labels)({x, y, z + depth}) = bw_labels({x, y, z});
            }
    return out;
}

}  // namespace liveset::bm_test
