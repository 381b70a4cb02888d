// Automatic brain mask (see brain_mask.hpp): histogram thresholds, morphology in mm, and the test
// that tells a skull-stripped input from a full head.
#include "liveset/segment/brain_mask.hpp"
#include "liveset/segment/brain_histogram.hpp"
#include "liveset/segment/head_geometry.hpp"
#include "liveset/segment/intensity.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "liveset/segment/morphology.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace {

using brain_detail::Histogram;
using brain_detail::kBins;
using brain_detail::Mask;
using brain_detail::Peak;
using brain_detail::Vertical;
using brain_detail::cranial;
using brain_detail::cut_contact_mm2;
using brain_detail::head_diameter_mm;
using brain_detail::head_top;
using brain_detail::surface_contact;
using brain_detail::vertical;
using brain_detail::deep_contrast;
using brain_detail::histogram;
using brain_detail::otsu3;
using brain_detail::quantile_above;
using brain_detail::quantiles_above;
using brain_detail::smoothed;
using brain_detail::smoothed_white_floor;
using brain_detail::tallest;
using brain_detail::white_matter_peak;

constexpr double kInf = std::numeric_limits<double>::infinity();

std::size_t count(const Mask& m) {
    return voxel_loops::count_if(m.size(), [&](std::size_t i) { return m[static_cast<PointIndex>(i)] != 0; });
}

// The image's lowest and highest values, and whether every voxel is finite (on every thread: min,
// max and the test are exact, so any split gives the serial loop's answer).
struct ValueRange {
    float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
    bool finite = true;
};

ValueRange value_range(const Grid<float>& image) {
    const float* const v = image.values().data();
    return voxel_loops::reduce(
        image.size(), voxel_loops::kBlock, ValueRange{},
        [&](std::size_t b, std::size_t e, ValueRange r) {
            for (std::size_t i = b; i != e; ++i) {
                r.finite = r.finite && std::isfinite(v[i]);
                r.lo = std::min(r.lo, v[i]);
                r.hi = std::max(r.hi, v[i]);
            }
            return r;
        },
        [](ValueRange a, const ValueRange& b) { return ValueRange{std::min(a.lo, b.lo), std::max(a.hi, b.hi), a.finite && b.finite}; });
}

// The image's range, after the checks every look starts with.
ValueRange check_image(const Grid<float>& image) {
    if (image.size() == 0) throw std::invalid_argument("brain mask: the image is empty");
    const ValueRange r = value_range(image);
    if (!r.finite) throw std::invalid_argument("brain mask: the image has NaN or infinite voxels");
    if (!(r.hi > r.lo)) throw std::invalid_argument("brain mask: the image is constant (every voxel is " + std::to_string(r.lo) + ")");
    return r;
}

// The image's lowest value when it fills at least 2 % of the voxels, as masking or resampling
// leaves the outside (a skull-stripped background, zeros beyond a resampled field of view). The
// image is finite (check_image).
std::optional<float> constant_fill(const Grid<float>& image) {
    const float lowest = value_range(image).lo;
    const float* const v = image.values().data();
    const std::size_t at_lowest = voxel_loops::count_if(image.size(), [&](std::size_t i) { return v[i] == lowest; });
    if (static_cast<double>(at_lowest) < 0.02 * static_cast<double>(image.size())) return std::nullopt;
    return lowest;
}

// A masked image's outside that does not lie below its tissue (a skull-stripped brain z-scored
// inside its mask with the outside left at 0, as nnU-Net-style preprocessing leaves it: the outside
// then reads as grey matter and the whole field of view as head). The exact value of at least half
// of the voxels on the array's six faces, when it fills at least 2 % of the image and at least 5 %
// of the rest lie below it (a few darker voxels — a resampler's undershoot at a stripped brain's
// edge, stray negatives in integer air — do not count); `outside` receives the voxels of that
// value connected to the faces. nullopt (and `outside` untouched) otherwise. `lowest`: the image's
// lowest value (check_image's range).
std::optional<float> mid_range_fill(const Grid<float>& image, float lowest, Mask& outside) {
    const Vec3i d = image.dims();
    std::vector<float> face;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y) {
            if (y == 0 || z == 0 || y == d.y - 1 || z == d.z - 1) {
                for (int x = 0; x < d.x; ++x) face.push_back(image({x, y, z}));
            } else {
                face.push_back(image({0, y, z}));
                if (d.x > 1) face.push_back(image({d.x - 1, y, z}));
            }
        }
    std::sort(face.begin(), face.end());
    float mode = face.front();
    std::size_t best = 0;
    for (std::size_t i = 0, j = 0; i < face.size(); i = j) {
        while (j < face.size() && face[j] == face[i]) ++j;
        if (j - i > best) best = j - i, mode = face[i];
    }
    if (2 * best < face.size()) return std::nullopt;
    if (!(lowest < mode)) return std::nullopt;  // constant_fill's case
    Mask inside(image.lattice());
    voxel_loops::for_each(inside.size(), [&](std::size_t i) { inside[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] != mode; });
    inside = fill_holes(inside);
    const std::size_t n_inside = count(inside);
    if (static_cast<double>(inside.size() - n_inside) < 0.02 * static_cast<double>(image.size())) return std::nullopt;
    // Within the tissue's range: a share of the inside lies below it, not a few.
    const std::size_t darker = voxel_loops::count_if(
        inside.size(), [&](std::size_t i) { return inside[static_cast<PointIndex>(i)] != 0 && image[static_cast<PointIndex>(i)] < mode; });
    if (static_cast<double>(darker) < 0.05 * static_cast<double>(n_inside)) return std::nullopt;  // air at 0 and a resampler's undershoot
    outside = std::move(inside);
    voxel_loops::for_each(outside.size(), [&](std::size_t i) { outside[static_cast<PointIndex>(i)] = outside[static_cast<PointIndex>(i)] == 0; });
    return mode;
}

// `image` with the voxels of `outside` set below all the others (by 1 % of the range), so that
// the masked outside is read as a skull-stripped image's dark background.
Grid<float> outside_lowered(const Grid<float>& image, const Mask& outside) {
    Grid<float> out = image;
    lower_voxels(out, outside);
    return out;
}

// The background's noise level (Sijbers et al. 2007; Brummer et al. 1993): the air around a head in
// a magnitude image is Rayleigh distributed, its histogram's mode lying σ above the floor. Returns σ
// (image units above `floor`), or 0 when the histogram over [floor, top] (bins of 1/64 of
// base − floor, smoothed over 2 bins) has no such mode below `base`: its first bin that is the
// highest up to three times its own distance from the floor, if it falls to half its height within
// that reach and holds `min_share` of all voxels within twice its distance; σ is then the middle of
// the bins around it at ≥ 90 % of its height (Rayleigh: 0.69σ..1.35σ, so 1.02σ; one noisy bin does
// not move it). A noise-free background is a spike at the floor (σ 0); a cropped scan's first peak
// (its CSF) is outgrown by grey and white matter.
double background_noise(const Grid<float>& image, double floor, double base, double top, double min_share) {
    if (!(base > floor) || !(top > base)) return 0.0;
    const double width = (base - floor) / 64;
    const int bins = static_cast<int>(std::min(1024.0, std::ceil((top - floor) / width)));
    const std::vector<std::size_t> n = voxel_loops::histogram(image.size(), static_cast<std::size_t>(bins), [&](std::size_t i) {
        const double k = (image[static_cast<PointIndex>(i)] - floor) / width;
        return k >= 0 && k < bins ? static_cast<std::size_t>(k) : static_cast<std::size_t>(bins);
    });
    const std::vector<double> c(n.begin(), n.end());
    const std::vector<double> s = smoothed(c, 2.0);
    const auto at = [&](int i) { return s[static_cast<std::size_t>(i)]; };
    for (int peak = 1; peak < 64 && 3 * peak + 1 < bins; ++peak) {  // a mode above `base` is no background
        const int reach = 3 * peak + 1;
        bool highest = true;
        for (int i = 0; i <= reach && highest; ++i) highest = i == peak || at(i) < at(peak) || (i > peak && at(i) == at(peak));
        if (!highest) continue;
        double lowest_after = at(peak), near = 0;
        for (int i = peak; i <= reach; ++i) lowest_after = std::min(lowest_after, at(i));
        for (int i = 0; i <= 2 * peak + 1; ++i) near += c[static_cast<std::size_t>(i)];
        if (lowest_after > 0.5 * at(peak) || near < min_share * static_cast<double>(image.size())) return 0.0;
        int lo = peak, hi = peak;  // the mode: the middle of the top (≥ 90 %), not its noisiest bin
        while (lo > 0 && at(lo - 1) >= 0.9 * at(peak)) --lo;
        while (hi < reach && at(hi + 1) >= 0.9 * at(peak)) ++hi;
        return 0.5 * (lo + hi + 1) * width;
    }
    return 0.0;
}

// The background threshold p2 + fraction·(p98 − p2), with p98 taken over the voxels above p2 so
// that a small head in a large empty field still has a range; and the head threshold: the same,
// raised to floor + noise_multiple·σ when the air is noisy enough to cross it (floor: the 0.1st
// percentile, a constant fill left out; σ: background_noise).
void thresholds(const Grid<float>& image, const BrainMaskOptions& o, BrainMaskReport& r) {
    double floor = 0.0, p2 = 0.0;
    if (const std::optional<float> fill = constant_fill(image)) {
        floor = quantile_above(image, nullptr, *fill, 0.001).value_or(0.0f);
        p2 = *quantile_above(image, nullptr, -kInf, 0.02);
    } else {
        constexpr std::array<double, 2> kFloorAndP2{0.001, 0.02};
        const std::vector<float> q = quantiles_above(image, nullptr, -kInf, kFloorAndP2);
        floor = q.at(0);
        p2 = q.at(1);
    }
    const std::optional<float> p98 = quantile_above(image, nullptr, p2, 0.98);
    if (!p98) throw std::invalid_argument("brain mask: no head found (98% of the voxels share the lowest value)");
    r.background_threshold = p2 + o.background_fraction * (*p98 - p2);
    r.background_noise = o.noise_multiple > 0 ? background_noise(image, floor, r.background_threshold, *p98, o.noise_min_share) : 0.0;
    r.head_threshold = r.background_noise > 0 ? std::max(r.background_threshold, floor + o.noise_multiple * r.background_noise)
                                               : r.background_threshold;
}

double max_spacing(const Lattice& l) { return std::max({l.spacing().x, l.spacing().y, l.spacing().z}); }

// The foreground above `threshold`: its components of at least a tenth of the largest (the skull can
// part scalp from brain); throws when it has no solid part (noise passes a threshold as scattered
// voxels that a few mm of erosion removes).
Mask head_foreground(const Grid<float>& image, double threshold) {
    Mask f(image.lattice());
    voxel_loops::for_each(f.size(), [&](std::size_t i) { f[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] > threshold; });
    f = large_components(f, 0.1);
    const std::size_t n = count(f);
    const double r = std::max(3.0, 2.0 * max_spacing(image.lattice()));
    if (n == 0 || static_cast<double>(count(erode_mm(f, r))) < 0.05 * static_cast<double>(n))
        throw std::invalid_argument("brain mask: no head found (the foreground has no solid part: noise or an empty scan?)");
    return f;
}

// A skull-stripped input: the filled largest component of everything above the background (the
// lowest value when it fills at least 2 % of the image, as masking leaves it; else the head threshold).
Mask stripped_foreground(const Grid<float>& image, double threshold) {
    const std::optional<float> fill = constant_fill(image);
    const double floor = fill ? *fill : threshold;
    Mask f(image.lattice());
    voxel_loops::for_each(f.size(), [&](std::size_t i) { f[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] > floor; });
    return fill_holes(largest_component(f));
}

Mask intersect(Mask a, const Mask& b) {
    voxel_loops::for_each(a.size(), [&](std::size_t i) { a[static_cast<PointIndex>(i)] &= b[static_cast<PointIndex>(i)] != 0; });
    return a;
}

// The brain and the voxels of `head` brighter than `above` (on `smooth`) within `reach_mm` that join
// it: a T2's or PD's CSF about the brain, above its window (GM peak + 4 σ, a fifth of the way to
// CSF where a T1's lower cut lies halfway). Without it a T2's mask held 57 % of the CSF, the model's
// pure CSF class failed and GM's window ended at 136, not 179 (GM Dice 0.873 → 0.946; BENCHMARKS.md,
// session 67). The dark skull stops it. Taken once the cut is settled: the CSF about the brainstem
// widened the brain's cross-section there and the head read as tilted, its neck taken in.
Mask with_bright_csf(const Mask& brain, const Mask& head, const Grid<float>& smooth, double above, double reach_mm) {
    Mask grown = dilate_mm(brain, reach_mm);
    voxel_loops::for_each(grown.size(), [&](std::size_t i) {
        const auto p = static_cast<PointIndex>(i);
        grown[p] = brain[p] != 0 || (grown[p] != 0 && head[p] != 0 && smooth[p] > above);
    });
    grown = largest_component(grown);
    voxel_loops::for_each(grown.size(), [&](std::size_t i) { grown[static_cast<PointIndex>(i)] |= brain[static_cast<PointIndex>(i)]; });  // nothing lost
    return fill_holes(grown);
}

// Tissue window → erosion → largest component → regrowth inside the window → fill → close → rim.
Mask extract_brain(const Grid<float>& image, const Grid<float>& smooth, const Mask& head, const BrainMaskOptions& o, BrainMaskReport& r) {
    Mask tissue(image.lattice());
    voxel_loops::for_each(tissue.size(), [&](std::size_t i) {
        const double v = smooth[static_cast<PointIndex>(i)];
        tissue[static_cast<PointIndex>(i)] = head[static_cast<PointIndex>(i)] != 0 && v >= r.tissue_low && v <= r.tissue_high;
    });
    r.tissue_voxels = count(tissue);
    const Mask core = largest_component(erode_mm(tissue, o.erosion_mm));
    r.core_voxels = count(core);
    if (r.core_voxels == 0)
        throw NoBrainFound("brain mask: the mask is empty (no brain tissue survives a " + std::to_string(o.erosion_mm) + " mm erosion)");
    Mask brain = fill_holes(largest_component(intersect(dilate_mm(core, o.erosion_mm + o.regrow_margin_mm), tissue)));
    brain = fill_holes(close_mm(brain, o.closing_mm));
    if (o.rim_mm > 0) {
        Mask rim = dilate_mm(brain, o.rim_mm);
        voxel_loops::for_each(rim.size(), [&](std::size_t i) {
            const auto p = static_cast<PointIndex>(i);
            rim[p] = static_cast<std::uint8_t>(brain[p] | (rim[p] & (head[p] != 0 && image[p] > r.background_threshold)));
        });
        brain = fill_holes(rim);
    }
    return brain;
}

// Grey matter's peak in the head above WM + 3 σ (the tallest there, standing inside that range, with
// its σ from the upper half width), or nullopt.
std::optional<std::pair<double, double>> grey_peak_above(const Grid<float>& image, const Mask& head, double top, const BrainMaskReport& r) {
    const double lo = r.wm_peak + 3 * r.wm_sigma;
    if (!(top > lo)) return std::nullopt;
    const Histogram h = histogram(image, head, lo, top);
    const Peak gm = tallest(smoothed(h.counts, 2.0));
    if (gm.bin == 0 || gm.high == kBins - 1) return std::nullopt;
    return std::pair{h.centre(gm.bin), std::max(h.width, (h.centre(gm.high) - h.centre(gm.bin)) / 1.1774)};
}

// The brain-tissue window and the brain it gives. A T1: the CSF/skin | GM/muscle cut (3-class Otsu up
// to WM) to WM + 4 σ. Grey matter brighter (T2, PD): WM − 3 σ of its darker side (muscle below) to grey
// matter's peak + 4 σ (grey_peak_above; without one, the T1 window), its lower end read on the smoothed
// image the window is applied to (smoothed_white_floor: a noisy T2's muscle below it; t2_ric9's mask
// was the whole head). `flair` (a T1 reading; flair_brain checks its peak): the same from
// flair_grey_peak. r.contrast and r.flair say which was taken.
Mask brain_of_contrast(const Grid<float>& image, const Grid<float>& smooth, const Mask& head, const Grid<float>& depth,
                       const BrainMaskOptions& o, TissueContrast contrast, bool flair, double top, BrainMaskReport& r) {
    std::optional<std::pair<double, double>> gm;
    if (contrast == TissueContrast::kGreyBrighter)
        gm = std::isfinite(r.deep_grey_peak) ? std::pair{r.deep_grey_peak, r.deep_grey_sigma} : grey_peak_above(image, head, top, r);
    r.contrast = gm ? TissueContrast::kGreyBrighter : TissueContrast::kT1;
    r.flair = flair && !gm;
    if (r.flair) gm = std::pair{r.flair_grey_peak, r.flair_grey_sigma};  // mirrored; the CSF is dark, `contrast` a T1's
    if (gm) {
        r.tissue_low = smoothed_white_floor(smooth, head, depth, r, top);
        r.tissue_high = gm->first + 4 * gm->second;
    } else {
        const Histogram h = histogram(image, head, r.background_threshold, r.wm_peak + 3 * r.wm_sigma);
        r.tissue_low = h.lo + otsu3(h.counts, h).first * h.width;
        r.tissue_high = r.wm_peak + 4 * r.wm_sigma;
    }
    return extract_brain(image, smooth, head, o, r);
}

// A head tilted in the field of view (pitched, rolled) reaches further below its top than an
// upright one, and its cut took the lower temporal lobe and cerebellum: where the brain meets the
// cut over more than cut_contact_mm2, it is extracted again, with the first look's tissue window
// (a neck never reads it), from the head cut kExtendStepMm lower, up to kExtendMaxMm. A look that
// adds more than kExtendMaxGrowth of the first mask is not a brain's lower edge (tilts of 5-30°
// add 1-6 %: tissue joined through the brainstem to a neck) and ends the search, unkept.
constexpr double kExtendStepMm = 15.0, kExtendMaxMm = 60.0, kExtendMaxGrowth = 0.15;
Mask below_the_cut(const Grid<float>& image, const Grid<float>& smooth, const Mask& whole_head, const Vertical& up,
                   const BrainMaskOptions& o, Mask brain, BrainMaskReport& r) {
    const double first_extent = r.brain_extent_mm;
    const std::size_t first_voxels = r.mask_voxels;
    const double top = head_top(whole_head, up);
    r.cut_contact_mm2 = cut_contact_mm2(brain, up, top - first_extent);
    if (o.cut_contact_mm2 <= 0) return brain;
    double contact = r.cut_contact_mm2;
    for (double extent = first_extent + kExtendStepMm; contact > o.cut_contact_mm2 && extent <= first_extent + kExtendMaxMm + 1e-9;
         extent += kExtendStepMm) {
        BrainMaskReport again = r;
        const Mask head = cranial(whole_head, up, extent, again.below_voxels);
        again.head_voxels = count(head);
        again.brain_extent_mm = extent;
        Mask lower = extract_brain(image, smooth, head, o, again);
        again.mask_voxels = count(lower);
        if (again.mask_voxels <= r.mask_voxels ||
            static_cast<double>(again.mask_voxels) > (1.0 + kExtendMaxGrowth) * static_cast<double>(first_voxels))
            break;
        brain = std::move(lower);
        r = again;
        contact = cut_contact_mm2(brain, up, top - extent);
    }
    return brain;
}

// A FLAIR read as a T1: its T1 window holds the muscle and the mask (`brain`) reaches the head's
// surface. Only then is the window mirrored from a grey-matter peak above white matter's
// (flair_grey_peak), and that mask kept where it keeps off the surface; and only in a head too large
// for a skull-stripped brain (kFlairHeadMinMl): a strongly biased T1 has such a peak too (bright white
// matter above a darkened part), and stripped, its T1 mask touches the surface as every stripped
// brain's does, where the mirrored window would keep its white matter alone.
constexpr double kFlairHeadMinMl = 2500.0;  // the largest adult intracranial volumes: about 2 L
Mask flair_brain(const Grid<float>& image, const Grid<float>& smooth, const Mask& head, const Grid<float>& depth, const BrainMaskOptions& o,
                 double top, Mask brain, BrainMaskReport& r) {
    const Vec3d sp = image.lattice().spacing();
    if (!std::isfinite(r.flair_grey_peak) || !(r.wm_peak - 3 * r.wm_low_sigma > r.background_threshold) ||
        static_cast<double>(r.head_voxels) * sp.x * sp.y * sp.z < kFlairHeadMinMl * 1000.0)
        return brain;
    BrainMaskReport again = r;
    Mask flair;
    try {
        flair = brain_of_contrast(image, smooth, head, depth, o, TissueContrast::kT1, true, top, again);
    } catch (const std::invalid_argument&) {
        return brain;  // nothing survives the erosion in that window: the T1 look stays
    }
    again.surface_contact = surface_contact(flair, depth, o.stripped_near_mm);
    if (again.surface_contact >= o.stripped_fraction) return brain;
    r = again;
    return flair;
}

// The brain in the head within `extent_mm` of its top (0: all of it): the tissue window, the
// extraction, the skull-stripped test, `r` filled in. An empty mask when none is found (under
// min_head_share of that head, not skull-stripped).
Mask brain_within(const Grid<float>& image, const Grid<float>& smooth, const Mask& whole_head, const Grid<float>& depth, const Vertical& up,
                  double extent_mm, const BrainMaskOptions& o, BrainMaskReport& r, double swamped_share = 1.0) {
    const Mask head = cranial(whole_head, up, extent_mm, r.below_voxels);
    r.brain_extent_mm = extent_mm;
    r.head_voxels = count(head);
    const double top = white_matter_peak(image, head, depth, r, false, swamped_share);
    const TissueContrast contrast = deep_contrast(r, true);
    Mask brain = brain_of_contrast(image, smooth, head, depth, o, contrast, false, top, r);
    r.surface_contact = surface_contact(brain, depth, o.stripped_near_mm);
    if (contrast == TissueContrast::kT1 && r.surface_contact >= o.stripped_fraction)
        brain = flair_brain(image, smooth, head, depth, o, top, std::move(brain), r);
    r.skull_stripped = o.detect_skull_stripped && r.surface_contact >= o.stripped_fraction;
    if (r.skull_stripped) brain = stripped_foreground(image, r.head_threshold);
    r.mask_voxels = count(brain);
    if (r.mask_voxels == 0) throw NoBrainFound("brain mask: the mask is empty");
    const double share = static_cast<double>(r.mask_voxels) / static_cast<double>(std::max<std::size_t>(r.head_voxels, 1));
    if (!r.skull_stripped && share < o.min_head_share) return Mask();
    return brain;
}

}  // namespace

void validate(const BrainMaskOptions& o) {
    auto require = [](bool ok, const char* what) {
        if (!ok) throw std::invalid_argument(std::string("brain mask options: ") + what);
    };
    require(std::isfinite(o.background_fraction) && o.background_fraction > 0 && o.background_fraction < 1,
            "background_fraction must lie in (0, 1)");
    require(std::isfinite(o.noise_multiple) && o.noise_multiple >= 0 && o.noise_multiple <= 10, "noise_multiple must lie in [0, 10]");
    require(std::isfinite(o.noise_min_share) && o.noise_min_share > 0 && o.noise_min_share < 1, "noise_min_share must lie in (0, 1)");
    require(std::isfinite(o.min_head_share) && o.min_head_share >= 0 && o.min_head_share < 1, "min_head_share must lie in [0, 1)");
    require(std::isfinite(o.smoothing_mm) && o.smoothing_mm >= 0 && o.smoothing_mm <= 10, "smoothing_mm must lie in [0, 10]");
    require(std::isfinite(o.erosion_mm) && o.erosion_mm > 0 && o.erosion_mm <= 50, "erosion_mm must lie in (0, 50]");
    require(std::isfinite(o.regrow_margin_mm) && o.regrow_margin_mm >= 0 && o.regrow_margin_mm <= 50, "regrow_margin_mm must lie in [0, 50]");
    require(std::isfinite(o.closing_mm) && o.closing_mm >= 0 && o.closing_mm <= 50, "closing_mm must lie in [0, 50]");
    require(std::isfinite(o.rim_mm) && o.rim_mm >= 0 && o.rim_mm <= 50, "rim_mm must lie in [0, 50]");
    require(std::isfinite(o.csf_reach_mm) && o.csf_reach_mm >= 0 && o.csf_reach_mm <= 50, "csf_reach_mm must lie in [0, 50]");
    require(std::isfinite(o.head_closing_mm) && o.head_closing_mm >= 0 && o.head_closing_mm <= 50, "head_closing_mm must lie in [0, 50]");
    require(std::isfinite(o.brain_extent_mm) && (o.brain_extent_mm == 0 || (o.brain_extent_mm >= 100 && o.brain_extent_mm <= 1000)),
            "brain_extent_mm must be 0 (the whole head) or lie in [100, 1000]");
    require(std::isfinite(o.adult_head_mm) && o.adult_head_mm >= 50 && o.adult_head_mm <= 500, "adult_head_mm must lie in [50, 500]");
    require(std::isfinite(o.neck_exit_mm2) && o.neck_exit_mm2 >= 0 && o.neck_exit_mm2 <= 1e6, "neck_exit_mm2 must lie in [0, 1e6]");
    require(std::isfinite(o.cut_contact_mm2) && o.cut_contact_mm2 >= 0 && o.cut_contact_mm2 <= 1e6, "cut_contact_mm2 must lie in [0, 1e6]");
    require(std::isfinite(o.swamped_share) && o.swamped_share > 0 && o.swamped_share <= 1, "swamped_share must lie in (0, 1]");
    require(std::isfinite(o.stripped_near_mm) && o.stripped_near_mm > 0 && o.stripped_near_mm <= 50, "stripped_near_mm must lie in (0, 50]");
    require(std::isfinite(o.stripped_fraction) && o.stripped_fraction > 0 && o.stripped_fraction <= 1, "stripped_fraction must lie in (0, 1]");
}

namespace {

// What look_for_brain found: the brain (empty: none), whether a child's scaled look was taken, and
// the first look's own reason where it threw (NoBrainFound: nothing survived the erosion).
struct Looked {
    Mask brain;
    bool child = false;
    std::string why;
};

// The brain looked for in turn, each look where those before found none: within `extent` of the
// head's top, within a child's scaled extent, and the last look (white matter's peak swamped,
// BrainMaskOptions::swamped_share) within `extent`, which is not kept where it reads the head as
// skull-stripped (the looks before read a full head). `first` (in: r's fields) receives the
// report of the look that found it, else the first look's.
Looked look_for_brain(const Grid<float>& image, const Grid<float>& smooth, const Mask& whole_head, const Grid<float>& depth, const Vertical& up,
                      double extent, const BrainMaskOptions& o, const BrainMaskReport& r, BrainMaskReport& first) {
    Looked out;
    try {
        out.brain = brain_within(image, smooth, whole_head, depth, up, extent, o, first);
    } catch (const NoBrainFound& e) {
        out.why = e.what();  // the first look's reason stands
    }
    const auto look = [&](double within, BrainMaskReport& into, double swamped_share) {  // a later look
        try {
            return brain_within(image, smooth, whole_head, depth, up, within, o, into, swamped_share);
        } catch (const NoBrainFound&) {
            return Mask();
        }
    };
    if (out.brain.size() == 0 && extent > 0) {  // a small head's neck inside an adult's extent: scaled to the head
        const double scaled = extent * std::clamp(r.head_diameter_mm / o.adult_head_mm, 0.6, 1.0);
        if (scaled < extent - 1.0) {
            out.child = true;
            BrainMaskReport again = r;
            out.brain = look(scaled, again, 1.0);
            if (out.brain.size() > 0) first = again;
        }
    }
    if (out.brain.size() == 0 && o.swamped_share < 1.0) {  // the last look: white matter's peak swamped
        BrainMaskReport again = r;
        out.brain = look(extent, again, o.swamped_share);
        if (out.brain.size() > 0 && !again.skull_stripped) first = again;
        else out.brain = Mask();
    }
    return out;
}

// auto_brain_mask on an image whose outside, if masked, is already below the rest.
Grid<std::uint8_t> find_brain(const Grid<float>& image, const BrainMaskOptions& o, BrainMaskReport* report, BrainMaskHead* known) {
    const bool reuse = known != nullptr && known->solid.size() > 0;
    BrainMaskReport r;
    thresholds(image, o, r);
    BrainMaskHead found;
    if (!reuse) {
        found.solid = fill_holes(close_mm(head_foreground(image, r.head_threshold), o.head_closing_mm));
        found.depth = depth_mm(found.solid);
    }
    const Mask& whole_head = reuse ? known->solid : found.solid;
    const Grid<float>& depth = reuse ? known->depth : found.depth;
    const Vertical up = vertical(whole_head, o.superior_from_header);
    r.inferior_exit_mm2 = up.exit_mm2;
    r.superior_from_header = o.superior_from_header;
    const Grid<float> smooth = gaussian_smooth(image, o.smoothing_mm);
    const double extent = up.exit_mm2 >= o.neck_exit_mm2 ? o.brain_extent_mm : 0.0;
    if (extent > 0) r.head_diameter_mm = head_diameter_mm(whole_head, up, 0.65 * extent);
    BrainMaskReport first = r;
    Looked looked = look_for_brain(image, smooth, whole_head, depth, up, extent, o, r, first);
    Mask brain = std::move(looked.brain);
    // Not after a child's scaled look (nor a last look after it): below it lies the neck the adult look failed on.
    if (brain.size() > 0 && !first.skull_stripped && !looked.child && extent > 0)
        brain = below_the_cut(image, smooth, whole_head, up, o, std::move(brain), first);
    if (brain.size() > 0 && !first.skull_stripped && first.contrast == TissueContrast::kGreyBrighter && o.csf_reach_mm > 0) {
        std::size_t below = 0;
        brain = with_bright_csf(brain, cranial(whole_head, up, first.brain_extent_mm, below), smooth, first.tissue_high, o.csf_reach_mm);
        const std::size_t voxels = count(brain);
        first.csf_voxels = voxels - first.mask_voxels;
        first.mask_voxels = voxels;
    }
    r = first;
    if (brain.size() == 0) {
        if (!looked.why.empty()) throw NoBrainFound(looked.why);
        char why[160];
        std::snprintf(why, sizeof why, "brain mask: no brain found (the mask holds %zu voxels, %.1f %% of the head, under %.1f %%)",
                      r.mask_voxels, 100.0 * static_cast<double>(r.mask_voxels) / static_cast<double>(std::max<std::size_t>(r.head_voxels, 1)),
                      100 * o.min_head_share);
        throw NoBrainFound(why);
    }
    const Vec3d s = image.lattice().spacing();
    r.mask_volume_mm3 = static_cast<double>(r.mask_voxels) * s.x * s.y * s.z;
    if (report != nullptr) *report = r;
    if (known != nullptr && !reuse) *known = std::move(found);
    return brain;
}

}  // namespace

Grid<std::uint8_t> auto_brain_mask(const Grid<float>& image, const BrainMaskOptions& o, BrainMaskReport* report, BrainMaskHead* known) {
    validate(o);
    const ValueRange range = check_image(image);
    const bool reuse = known != nullptr && known->solid.size() > 0;
    if (reuse && (!(known->solid.dims() == image.dims()) || !(known->depth.dims() == image.dims()) ||
                  (known->outside.size() > 0 && !(known->outside.dims() == image.dims()))))
        throw std::invalid_argument("brain mask: the head given is not of the image's size");
    Mask found;  // a masked outside found here (the head given keeps its own)
    double fill = reuse ? known->outside_value : std::numeric_limits<double>::quiet_NaN();
    if (!reuse)
        if (const std::optional<float> f = mid_range_fill(image, range.lo, found)) fill = *f;
    const Mask& outside = reuse ? known->outside : found;
    if (outside.size() == 0) return find_brain(image, o, report, known);
    // A masked outside within the tissue's range: read as a skull-stripped image's dark background.
    BrainMaskReport r;
    Grid<std::uint8_t> brain = find_brain(outside_lowered(image, outside), o, &r, known);
    r.mid_range_fill = fill;
    if (report != nullptr) *report = r;
    if (known != nullptr && !reuse) {
        known->outside = std::move(found);
        known->outside_value = fill;
    }
    return brain;
}

TissueContrast brain_contrast(const Grid<float>& image, const Grid<std::uint8_t>& brain, double* tissue_floor, bool known_grey_brighter) {
    if (tissue_floor) *tissue_floor = -std::numeric_limits<double>::infinity();
    if (!(brain.dims() == image.dims())) throw std::invalid_argument("brain mask: the region is not of the image's size");
    Mask finite(brain.lattice(), 0);  // the brain's voxels with a value (a masked scan's NaN outside it are not read)
    float low = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (brain[p] == 0 || !std::isfinite(image[p])) continue;
        finite[p] = 1;
        low = std::min(low, image[p]);
    }
    if (!std::isfinite(low)) return TissueContrast::kT1;
    BrainMaskReport r;  // no air inside a brain: every voxel of it counts
    r.background_threshold = std::nextafter(low, -std::numeric_limits<float>::infinity());
    try {
        white_matter_peak(image, finite, depth_mm(brain), r, known_grey_brighter);
    } catch (const std::invalid_argument&) {  // one value throughout
        return TissueContrast::kT1;
    }
    const TissueContrast contrast = known_grey_brighter ? TissueContrast::kGreyBrighter : deep_contrast(r, false);
    if (tissue_floor && contrast == TissueContrast::kGreyBrighter) *tissue_floor = r.wm_peak - 3.0 * r.wm_low_sigma;
    return contrast;
}

}  // namespace liveset
