// Holes of a segmented sheet without ground truth: gaps of sheet-like voxels joining the inner
// tissue to the outside (the rule is in holes.hpp).
#include "liveset/eval/holes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "liveset/eval/topology.hpp"

namespace liveset {

namespace {

constexpr std::uint8_t kSheet = 0, kInner = 1, kGap = 2, kOuter = 3, kOutside = 4;  // kOutside: counted outer

void check(const Grid<std::uint8_t>& mask, const Grid<float>& image, const Grid<std::uint8_t>* roi,
           const HoleFinderOptions& options) {
    options.validate();
    if (!(mask.dims() == image.dims()) || (roi && !(roi->dims() == mask.dims())))
        throw std::invalid_argument("find_holes: mask, image and ROI differ in size");
}

bool on_border(Vec3i c, Vec3i d) {
    return c.x == 0 || c.y == 0 || c.z == 0 || c.x == d.x - 1 || c.y == d.y - 1 || c.z == d.z - 1;
}

// Every voxel's kind; the outer voxels reachable (6-connected through outer voxels) from the ROI's
// exterior or the image border become kOutside.
std::vector<std::uint8_t> classify(const Grid<std::uint8_t>& mask, const Grid<float>& image,
                                   const Grid<std::uint8_t>* roi, const HoleFinderOptions& o) {
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    std::vector<std::uint8_t> kind(lat.size(), kSheet);
    std::vector<PointIndex> queue;
    for (PointIndex i = 0; i < lat.size(); ++i) {
        if (mask[i]) continue;
        const double v = image[i];
        if (roi && !(*roi)[i]) kind[i] = kOuter;
        else kind[i] = v >= o.sheet_upper ? kInner : (v >= o.sheet_lower ? kGap : kOuter);
        if (kind[i] == kOuter && ((roi && !(*roi)[i]) || on_border(lat.coord(i), d))) {
            kind[i] = kOutside;
            queue.push_back(i);
        }
    }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const Vec3i c = lat.coord(queue[head]);
        for (int f = 0; f < 6; ++f) {
            Vec3i q = c;
            q[f / 2] += (f % 2) ? 1 : -1;
            if (!lat.contains(q)) continue;
            const PointIndex j = lat.index(q);
            if (kind[j] != kOuter) continue;
            kind[j] = kOutside;
            queue.push_back(j);
        }
    }
    return kind;
}

struct Labelled {
    ComponentLabels label;  // gap components
    std::vector<std::uint8_t> keep;    // per label: touches inner and outside
    std::vector<std::uint8_t> rim;     // per voxel: a gap voxel touching inner or outside
    std::vector<std::size_t> size, sheet;  // per label: voxels, voxels touching the mask
};

Labelled label_gaps(const Grid<std::uint8_t>& mask, const Grid<float>& image, const Grid<std::uint8_t>* roi,
                    const HoleFinderOptions& o) {
    const Lattice& lat = mask.lattice();
    const std::vector<std::uint8_t> kind = classify(mask, image, roi, o);
    Grid<std::uint8_t> gap(lat, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) gap[i] = kind[i] == kGap;
    std::size_t count = 0;
    Labelled out;
    out.label = label_components(gap, 6, &count);
    std::vector<std::uint8_t> inner(count + 1, 0), outer(count + 1, 0);
    out.rim.assign(lat.size(), 0);
    out.size.assign(count + 1, 0);
    out.sheet.assign(count + 1, 0);
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = out.label[i];
        if (!k) continue;
        const Vec3i c = lat.coord(i);
        ++out.size[k];
        bool touches_sheet = false;
        for (int f = 0; f < 6; ++f) {
            Vec3i q = c;
            q[f / 2] += (f % 2) ? 1 : -1;
            const std::uint8_t kq = lat.contains(q) ? kind[lat.index(q)] : kOutside;
            if (kq == kInner) inner[k] = out.rim[i] = 1;
            if (kq == kOutside) outer[k] = out.rim[i] = 1;
            touches_sheet = touches_sheet || kq == kSheet;
        }
        out.sheet[k] += touches_sheet;
    }
    out.keep.assign(count + 1, 0);
    for (std::size_t k = 1; k <= count; ++k)
        out.keep[k] = inner[k] && outer[k] && out.size[k] >= o.min_voxels &&
                      static_cast<double>(out.sheet[k]) >= o.min_sheet_share * static_cast<double>(out.size[k]);
    return out;
}

}  // namespace

void HoleFinderOptions::validate() const {
    if (!(std::isfinite(sheet_lower) && std::isfinite(sheet_upper) && sheet_lower < sheet_upper))
        throw std::invalid_argument("hole finder: the sheet's band needs finite lower < upper intensities");
    if (!(min_sheet_share >= 0 && min_sheet_share <= 1))
        throw std::invalid_argument("hole finder: min_sheet_share must be in [0, 1]");
}

std::vector<HoleCandidate> find_holes(const Grid<std::uint8_t>& mask, const Grid<float>& image,
                                      const Grid<std::uint8_t>* roi, const HoleFinderOptions& options) {
    check(mask, image, roi, options);
    const Lattice& lat = mask.lattice();
    const Labelled g = label_gaps(mask, image, roi, options);
    const std::size_t count = g.keep.size() - 1;
    std::vector<std::size_t> size(count + 1, 0), rim(count + 1, 0);
    std::vector<Vec3d> sum(count + 1, Vec3d{0, 0, 0}), rim_sum(count + 1, Vec3d{0, 0, 0});
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = g.label[i];
        if (!k || !g.keep[k]) continue;
        const Vec3d c = lat.coord(i).cast<double>();
        ++size[k];
        sum[k] += c;
        if (g.rim[i]) {
            ++rim[k];
            rim_sum[k] += c;
        }
    }
    std::vector<std::size_t> slot(count + 1, SIZE_MAX);
    std::vector<HoleCandidate> out;
    std::vector<Vec3d> aim;
    for (std::size_t k = 1; k <= count; ++k) {
        if (!g.keep[k]) continue;
        slot[k] = out.size();
        out.push_back({size[k], rim[k], g.sheet[k], sum[k] / static_cast<double>(size[k]), Vec3i{0, 0, 0}});
        aim.push_back(rim_sum[k] / static_cast<double>(rim[k]));
    }
    std::vector<double> best(out.size(), 1e300);
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const std::uint32_t k = g.label[i];
        if (!k || slot[k] == SIZE_MAX) continue;
        const std::size_t j = slot[k];
        const Vec3d dv = lat.coord(i).cast<double>() - aim[j];
        if (dot(dv, dv) < best[j]) {
            best[j] = dot(dv, dv);
            out[j].site = lat.coord(i);
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const HoleCandidate& a, const HoleCandidate& b) {
        if (a.voxels != b.voxels) return a.voxels > b.voxels;
        const Vec3i p = a.site, q = b.site;
        if (p.z != q.z) return p.z < q.z;
        if (p.y != q.y) return p.y < q.y;
        return p.x < q.x;
    });
    return out;
}

Grid<std::uint8_t> hole_voxels(const Grid<std::uint8_t>& mask, const Grid<float>& image, const Grid<std::uint8_t>* roi,
                               const HoleFinderOptions& options) {
    check(mask, image, roi, options);
    const Labelled g = label_gaps(mask, image, roi, options);
    Grid<std::uint8_t> out(mask.lattice(), 0);
    for (PointIndex i = 0; i < out.size(); ++i) {
        const std::uint32_t k = g.label[i];
        out[i] = k && g.keep[k];
    }
    return out;
}

std::size_t hole_voxels_near(const Grid<std::uint8_t>& holes, Vec3d site, double radius) {
    const Lattice& lat = holes.lattice();
    const int r = static_cast<int>(std::ceil(radius));
    const Vec3i c{static_cast<int>(std::lround(site.x)), static_cast<int>(std::lround(site.y)),
                  static_cast<int>(std::lround(site.z))};
    std::size_t n = 0;
    for (int dz = -r; dz <= r; ++dz)
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const Vec3i q = c + Vec3i{dx, dy, dz};
                const Vec3d dv = q.cast<double>() - site;
                if (lat.contains(q) && dot(dv, dv) <= radius * radius && holes(q)) ++n;
            }
    return n;
}

long local_genus(const Grid<std::uint8_t>& mask, Vec3i c, int r) {
    if (r < 0) throw std::invalid_argument("local_genus: negative box half-width");
    const Vec3i d = mask.dims();
    const Vec3i lo{std::max(c.x - r, 0), std::max(c.y - r, 0), std::max(c.z - r, 0)};
    const Vec3i hi{std::min(c.x + r, d.x - 1), std::min(c.y + r, d.y - 1), std::min(c.z + r, d.z - 1)};
    if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return 0;
    Grid<std::uint8_t> box(Lattice(hi - lo + Vec3i{1, 1, 1}), 0);
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) box(Vec3i{x, y, z} - lo) = mask(Vec3i{x, y, z});
    return mask_topology(box).genus;
}

HoleVerdict hole_verdict(Vec3d site, double radius, const Grid<std::uint8_t>& holes_before, const Grid<std::uint8_t>& holes_after,
                         const Grid<std::uint8_t>& mask_before, const Grid<std::uint8_t>& mask_after) {
    HoleVerdict v;
    v.before = hole_voxels_near(holes_before, site, radius);
    v.after = hole_voxels_near(holes_after, site, radius);
    v.closed = 2 * v.after <= v.before;
    const Vec3i c{static_cast<int>(std::lround(site.x)), static_cast<int>(std::lround(site.y)), static_cast<int>(std::lround(site.z))};
    v.genus_before = local_genus(mask_before, c, 8);
    v.genus_after = local_genus(mask_after, c, 8);
    return v;
}

}  // namespace liveset
