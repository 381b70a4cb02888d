// Histogram helpers of the automatic brain mask and its reading of the deep head (brain_histogram.hpp).
#include "liveset/segment/brain_histogram.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "liveset/segment/tissue_model.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset::brain_detail {

// For each fraction q in [0, 1], the value at q of the sorted values of `image` inside `mask` (all
// voxels when null) that lie above `above` — element floor(q·(n − 1)), as std::nth_element places
// it — or nothing when there is none. By a histogram of the values' order-preserving bit patterns
// (their top 16 bits) and a selection among the values of the bins that hold the elements: two
// passes (in parallel blocks) for all the fractions, and no copy of the image.
std::vector<float> quantiles_above(const Grid<float>& image, const Mask* mask, double above, std::span<const double> fractions) {
    const float* const value = image.values().data();
    const std::uint8_t* const inside = mask != nullptr ? mask->values().data() : nullptr;
    // Calls `visit(i, key)` for every kept voxel of [b, e) (in the mask, above `above`: never NaN), its
    // value's order-preserving bit pattern as the key; the loops hold everything in locals.
    const auto for_kept = [value, inside, above](std::size_t b, std::size_t e, auto&& visit) {
        const auto key = [](float v) {
            const auto u = std::bit_cast<std::uint32_t>(v);
            return (u & 0x80000000u) != 0 ? ~u : (u | 0x80000000u);
        };
        if (inside == nullptr) {
            for (std::size_t i = b; i < e; ++i)
                if (value[i] > above) visit(i, key(value[i]));
        } else {
            for (std::size_t i = b; i < e; ++i)
                if (inside[i] != 0 && value[i] > above) visit(i, key(value[i]));
        }
    };
    // Each thread counts its blocks in its own 32-bit bins (a lattice holds fewer than 2^32 points);
    // the sums are exact whatever the blocks and threads.
    static_assert(kMaxLatticePoints <= 0xFFFF'FFFFull);
    constexpr std::size_t kBins = std::size_t{1} << 16, kBlock = std::size_t{1} << 16;
    tbb::enumerable_thread_specific<std::vector<std::uint32_t>> local([] { return std::vector<std::uint32_t>(kBins, 0); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, image.size(), kBlock), [&](const tbb::blocked_range<std::size_t>& r) {
        std::uint32_t* const bins = local.local().data();
        for_kept(r.begin(), r.end(), [bins](std::size_t, std::uint32_t k) { ++bins[k >> 16]; });
    });
    std::vector<std::size_t> bins(kBins, 0);
    for (const std::vector<std::uint32_t>& l : local)
        for (std::size_t b = 0; b < kBins; ++b) bins[b] += l[b];
    std::size_t n = 0;
    for (std::size_t c : bins) n += c;
    if (n == 0) return {};
    // Each fraction's bin and rank within it; the bins asked for numbered 1, 2, ... in `slot`.
    std::vector<std::uint8_t> slot(kBins, 0);
    std::vector<std::size_t> wanted;  // by slot - 1: the bin
    std::vector<std::pair<std::size_t, std::size_t>> at;  // per fraction: slot - 1, rank in the bin
    for (const double q : fractions) {
        auto k = static_cast<std::size_t>(q * static_cast<double>(n - 1));
        std::size_t bin = 0;
        while (k >= bins[bin]) k -= bins[bin++];
        if (slot[bin] == 0) {
            if (wanted.size() == 255) throw std::invalid_argument("quantiles_above: at most 255 distinct bins");
            wanted.push_back(bin);
            slot[bin] = static_cast<std::uint8_t>(wanted.size());
        }
        at.emplace_back(slot[bin] - 1u, k);
    }
    // The asked bins' values, gathered per block in any order: the k-th of a bin is one value
    // whatever the order (a bin never holds both zeros, whose keys differ in the top bit).
    tbb::enumerable_thread_specific<std::vector<std::vector<float>>> found([&] { return std::vector<std::vector<float>>(wanted.size()); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, image.size(), kBlock), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<std::vector<float>>& f = found.local();
        const std::uint8_t* const to = slot.data();
        for_kept(r.begin(), r.end(), [&f, value, to](std::size_t i, std::uint32_t k) {
            if (const std::uint8_t s = to[k >> 16]; s != 0) f[s - 1u].push_back(value[i]);
        });
    });
    std::vector<std::vector<float>> in_bin(wanted.size());
    for (std::size_t w = 0; w < wanted.size(); ++w) {
        in_bin[w].reserve(bins[wanted[w]]);
        for (const std::vector<std::vector<float>>& f : found) in_bin[w].insert(in_bin[w].end(), f[w].begin(), f[w].end());
    }
    std::vector<float> out;
    out.reserve(fractions.size());
    for (const auto& [w, k] : at) {
        std::vector<float>& v = in_bin[w];
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
        out.push_back(v[k]);
    }
    return out;
}

std::optional<float> quantile_above(const Grid<float>& image, const Mask* mask, double above, double q) {
    const std::vector<float> v = quantiles_above(image, mask, above, std::span<const double>(&q, 1));
    if (v.empty()) return std::nullopt;
    return v[0];
}

Histogram histogram(const Grid<float>& image, const Mask& mask, double lo, double hi) {
    Histogram h;
    h.lo = lo;
    h.width = (hi - lo) / kBins;
    const std::vector<std::size_t> counts = voxel_loops::histogram(image.size(), kBins, [&](std::size_t i) {
        const double v = image[static_cast<PointIndex>(i)];
        if (mask[static_cast<PointIndex>(i)] == 0 || !(v >= lo && v <= hi)) return std::size_t{kBins};  // NaN too
        return static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>((v - lo) / h.width)));
    });
    for (int k = 0; k < kBins; ++k) h.counts[static_cast<std::size_t>(k)] = static_cast<double>(counts[static_cast<std::size_t>(k)]);
    return h;
}

std::vector<double> smoothed(const std::vector<double>& c, double sigma_bins) {
    const int r = static_cast<int>(std::ceil(3 * sigma_bins));
    std::vector<double> out(c.size(), 0.0);
    for (int i = 0; i < static_cast<int>(c.size()); ++i)
        for (int k = -r; k <= r; ++k) {
            const int j = std::clamp(i + k, 0, static_cast<int>(c.size()) - 1);
            out[static_cast<std::size_t>(i)] += c[static_cast<std::size_t>(j)] * std::exp(-0.5 * k * k / (sigma_bins * sigma_bins));
        }
    return out;
}

std::pair<int, int> otsu3(const std::vector<double>& h, const Histogram& geom) {
    std::vector<double> centres(h.size());
    for (std::size_t i = 0; i < h.size(); ++i) centres[i] = geom.centre(static_cast<int>(i));
    const std::vector<std::size_t> s = otsu_split_bins(h, centres, 3);
    return {static_cast<int>(s[0]), static_cast<int>(s[1])};
}

Peak tallest(const std::vector<double>& s) {
    Peak p{static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin())};
    const double half = 0.5 * s[static_cast<std::size_t>(p.bin)];
    for (p.high = p.bin; p.high < kBins - 1 && s[static_cast<std::size_t>(p.high)] > half;) ++p.high;
    for (p.low = p.bin; p.low > 0 && s[static_cast<std::size_t>(p.low)] > half;) --p.low;
    return p;
}

namespace {

// A peak of smoothed histogram `s` at `bin`, each side's half width ending where it falls to half the
// peak's height or, before that, at the valley that parts it from a neighbour.
Peak peak_at(const std::vector<double>& s, int bin) {
    Peak p{bin, bin, bin};
    const double half = 0.5 * s[static_cast<std::size_t>(bin)];
    const auto at = [&](int i) { return s[static_cast<std::size_t>(i)]; };
    while (p.high < kBins - 1 && at(p.high) > half && at(p.high + 1) <= at(p.high)) ++p.high;
    while (p.low > 0 && at(p.low) > half && at(p.low - 1) <= at(p.low)) --p.low;
    return p;
}

constexpr double kSecondPeak = 0.05;
constexpr double kGreyShare = 0.1;  // T1 heads: ≤ 0.056 above; PDs and T2s measured: 0.25-0.57

// The peaks of smoothed histogram `s` that stand inside it (no end bin) with a prominence of at least
// kSecondPeak of the tallest bin, most prominent first: (prominence, bin). A peak's prominence: its
// height over the higher of the two lowest points that part it from a taller peak or from the end.
std::vector<std::pair<double, int>> prominent_peaks(const std::vector<double>& s) {
    const double tallest_bin = *std::max_element(s.begin(), s.end());
    std::vector<std::pair<double, int>> peaks;
    for (int b = 1; b + 1 < kBins; ++b) {
        const double v = s[static_cast<std::size_t>(b)];
        if (!(v > s[static_cast<std::size_t>(b - 1)] && v >= s[static_cast<std::size_t>(b + 1)])) continue;
        double left = v, right = v;
        for (int i = b - 1; i >= 0 && s[static_cast<std::size_t>(i)] <= v; --i) left = std::min(left, s[static_cast<std::size_t>(i)]);
        for (int i = b + 1; i < kBins && s[static_cast<std::size_t>(i)] <= v; ++i) right = std::min(right, s[static_cast<std::size_t>(i)]);
        if (const double prominence = v - std::max(left, right); prominence >= kSecondPeak * tallest_bin) peaks.emplace_back(prominence, b);
    }
    std::sort(peaks.begin(), peaks.end(), [](const auto& x, const auto& y) { return x.first > y.first || (x.first == y.first && x.second < y.second); });
    return peaks;
}

// The two most prominent peaks of smoothed histogram `s`, darker first.
std::optional<std::pair<Peak, Peak>> two_peaks(const std::vector<double>& s) {
    const std::vector<std::pair<double, int>> peaks = prominent_peaks(s);
    if (peaks.size() < 2) return std::nullopt;
    const int a = std::min(peaks[0].second, peaks[1].second), b = std::max(peaks[0].second, peaks[1].second);
    return std::pair{peak_at(s, a), peak_at(s, b)};
}

// The brightest prominent peak of smoothed histogram `s` above its tallest, if any.
std::optional<Peak> brightest_above_tallest(const std::vector<double>& s) {
    const int wm = tallest(s).bin;
    int brightest = wm;
    for (const auto& [prominence, bin] : prominent_peaks(s)) brightest = std::max(brightest, bin);
    if (brightest == wm) return std::nullopt;
    return peak_at(s, brightest);
}

// The deepest half of `head` by `depth`: its voxels at least half as deep as the deepest.
// In parallel blocks (a maximum over fixed parts: the same on any thread count).
Mask deep_half(const Mask& head, const Grid<float>& depth) {
    const float deepest = voxel_loops::reduce(
        head.size(), voxel_loops::kBlock, 0.0f,
        [&](std::size_t b, std::size_t e, float d) {
            for (std::size_t i = b; i != e; ++i)
                if (head[static_cast<PointIndex>(i)] != 0) d = std::max(d, depth[static_cast<PointIndex>(i)]);
            return d;
        },
        [](float a, float b) { return std::max(a, b); });
    Mask deep(head.lattice());
    voxel_loops::for_each(head.size(), [&](std::size_t i) {
        deep[static_cast<PointIndex>(i)] = head[static_cast<PointIndex>(i)] != 0 && depth[static_cast<PointIndex>(i)] >= 0.5f * deepest;
    });
    return deep;
}

}  // namespace

double white_matter_peak(const Grid<float>& image, const Mask& head, const Grid<float>& depth, BrainMaskReport& r, bool grey_brighter,
                         double swamped_share) {
    const Mask deep = deep_half(head, depth);
    r.deep_grey_peak = r.flair_grey_peak = std::numeric_limits<double>::quiet_NaN();
    r.flair_grey_sigma = 0;
    const std::optional<float> top = quantile_above(image, &head, r.background_threshold, 0.995);
    if (!top) throw std::invalid_argument("brain mask: no head found (nothing above the background inside the head)");
    if (!(*top > r.background_threshold)) throw std::invalid_argument("brain mask: no brain tissue found (the head has no contrast)");
    const Histogram h = histogram(image, deep, r.background_threshold, *top);
    const std::vector<double> s = smoothed(h.counts, 2.0);
    const auto take = [&](const Peak& p, BrainMaskReport& into) {  // a peak as white matter's, and the shares about it
        into.wm_peak = h.centre(p.bin);
        into.wm_sigma = std::max(h.width, (h.centre(p.high) - into.wm_peak) / 1.1774);
        into.wm_low_sigma = std::max(h.width, (into.wm_peak - h.centre(p.low)) / 1.1774);
        into.deep_above = into.deep_below = 0;
        const double narrow = std::min(into.wm_sigma, into.wm_low_sigma);
        // The deep voxels above the background: 3 σ above (bin 0), 3 σ below (1), between (2).
        const double hi = into.wm_peak + 3 * narrow, lo = into.wm_peak - 3 * narrow;
        const std::vector<std::size_t> c = voxel_loops::histogram(deep.size(), 3, [&](std::size_t k) -> std::size_t {
            const double x = image[static_cast<PointIndex>(k)];
            if (deep[static_cast<PointIndex>(k)] == 0 || !(x > r.background_threshold)) return 3;
            return x > hi ? 0 : x < lo ? 1 : 2;
        });
        const double n = static_cast<double>(c[0] + c[1] + c[2]);
        if (n > 0) into.deep_above = static_cast<double>(c[0]) / n, into.deep_below = static_cast<double>(c[1]) / n;
    };
    // White matter: the tallest peak (a T1's deep head is mostly white matter).
    take(tallest(s), r);
    r.deep_grey_peak = std::numeric_limits<double>::quiet_NaN();
    r.wm_swamped = false;
    // Which side of white matter grey matter and CSF lie on (deep_contrast): the deep voxels above the background.
    constexpr std::array<double, 3> kDeciles{0.1, 0.5, 0.9};
    const std::vector<float> q = quantiles_above(image, &deep, r.background_threshold, kDeciles);
    if (q.empty()) return *top;
    const double q10 = q[0], q50 = q[1], q90 = q[2];
    r.deep_skew = q90 > q10 ? (q90 + q10 - 2.0 * q50) / (q90 - q10) : 0.0;
    // Swamped (the last look): the brightest prominent peak, in a deep head skewed dark as a T1's
    // (a T2's or PD's brightest is its CSF).
    if (!grey_brighter && swamped_share < 1.0 && r.deep_skew < 0.0 && r.deep_above > swamped_share)
        if (const std::optional<Peak> brightest = brightest_above_tallest(s)) {
            take(*brightest, r);
            r.wm_swamped = true;
        }
    // Skewed bright with two peaks standing out: the darker white matter's, the brighter grey
    // matter's (a PD's grey matter can outnumber its white matter there, and a low grey-white
    // contrast puts it within 3 σ of it), where that reads as grey brighter: at least kGreyShare of
    // the deep head 3 σ above that white matter, over twice as much as below, and white matter 3 σ
    // clear of the background. Else the tallest stays. Known grey-brighter (a corrected image whose
    // field took part of that contrast), two peaks are read so whatever the shares: the tallest may
    // be grey matter's, and the floor below white matter (brain_contrast) would cut white matter.
    if ((r.deep_skew > 0.0 || grey_brighter) && !r.wm_swamped)
        if (const auto two = two_peaks(s)) {
            BrainMaskReport alt = r;
            take(two->first, alt);
            if (grey_brighter || (alt.deep_above >= kGreyShare && alt.deep_above > 2.0 * alt.deep_below &&
                                  alt.wm_peak - 3.0 * alt.wm_low_sigma > r.background_threshold)) {
                alt.deep_grey_peak = h.centre(two->second.bin);
                alt.deep_grey_sigma = std::max(h.width, (h.centre(two->second.high) - alt.deep_grey_peak) / 1.1774);
                r = alt;
            }
        }
    // A FLAIR: grey matter brighter than white with CSF dark, far below (the skew then reads a T1's).
    // Not read as grey brighter, a prominent peak above the tallest (white matter's) with at least
    // kGreyShare of the deep half 3 σ above that white matter reads as grey matter's, for the brain
    // mask's tissue window only (BrainMaskReport::flair_grey_peak).
    if (!grey_brighter && !r.wm_swamped && !std::isfinite(r.deep_grey_peak) && r.deep_above >= kGreyShare) {
        const int wm = tallest(s).bin;
        for (const auto& [prominence, bin] : prominent_peaks(s))
            if (bin > wm) {
                const Peak gm = peak_at(s, bin);
                r.flair_grey_peak = h.centre(gm.bin);
                r.flair_grey_sigma = std::max(h.width, (h.centre(gm.high) - r.flair_grey_peak) / 1.1774);
                break;
            }
    }
    return *top;
}

double smoothed_white_floor(const Grid<float>& smooth, const Mask& head, const Grid<float>& depth, const BrainMaskReport& r, double top) {
    const double lo = std::max(r.background_threshold, r.wm_peak - 3.0 * r.wm_low_sigma);
    if (!(top > lo)) return lo;
    const Histogram h = histogram(smooth, deep_half(head, depth), lo, top);
    const std::vector<double> s = smoothed(h.counts, 2.0);
    // The local maximum reached climbing from the raw white-matter peak's bin (not the tallest bin
    // near it: a PD's grey matter may outnumber white matter there), within 2 σ of that peak.
    const auto at = [&](int b) { return s[static_cast<std::size_t>(b)]; };
    int best = std::clamp(static_cast<int>((r.wm_peak - h.lo) / h.width), 0, kBins - 1);
    for (int next = best;; best = next) {
        if (best + 1 < kBins && at(best + 1) > at(next)) next = best + 1;
        if (best > 0 && at(best - 1) > at(next)) next = best - 1;
        if (next == best) break;
    }
    if (best <= 0 || best == kBins - 1 || !(at(best) > 0) ||
        std::abs(h.centre(best) - r.wm_peak) > 2.0 * std::max(r.wm_sigma, r.wm_low_sigma))
        return lo;
    const Peak p = peak_at(s, best);
    if (p.low == 0) return lo;  // its lower side runs off the histogram: not read
    const double sigma = std::max(h.width, (h.centre(p.bin) - h.centre(p.low)) / 1.1774);
    return std::max(lo, h.centre(p.bin) - 3.0 * sigma);
}

TissueContrast deep_contrast(const BrainMaskReport& r, bool in_head) {
    if (r.deep_skew > 0.0 && (std::isfinite(r.deep_grey_peak) || (r.deep_above >= 0.25 && r.deep_above > 4.0 * r.deep_below)) &&
        (!in_head || r.wm_peak - 3.0 * r.wm_low_sigma > r.background_threshold))
        return TissueContrast::kGreyBrighter;
    return TissueContrast::kT1;
}

}  // namespace liveset::brain_detail
