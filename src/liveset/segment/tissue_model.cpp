// Tissue intensity model: histogram, multi-level Otsu start, EM with partial-volume classes, window.
#include "liveset/segment/tissue_model.hpp"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <utility>
#include <sstream>
#include <stdexcept>

#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/grid/radix_sort.hpp"

namespace liveset {

namespace {

// A pure class below this share of the region is no class, however many voxels it shares with its
// neighbours (presence()).
constexpr double kMinPure = 0.005;
constexpr int kMixSteps = 16;  // fractions f = (t + ½)/16 sample the partial-volume classes
constexpr double kClearlyMoreLikely = 1e-3;  // nats per voxel (fit_tissue_model's two starts)

// One histogram bin: count, and the mean and variance of the values that fell into it.
struct Bin {
    double count = 0.0, mean = 0.0, var = 0.0;
};

double gauss(double x, double mean, double sigma) {
    const double z = (x - mean) / sigma;
    return std::exp(-0.5 * z * z) / (sigma * std::sqrt(2.0 * std::numbers::pi));
}

double quantile_sorted(std::span<const float> v, double q) {
    const double pos = q * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// Ascending order of finite floats by an LSD radix sort on their bits turned into unsigned order
// (the order std::sort gives, up to the order of −0 and +0, which no sum or quantile below
// tells apart); 1.8 M brain voxels sort in a few linear passes (std::sort took 6 % of a set-up).
void sort_values(LargeVector<float>& v) {
    LargeVector<float> scratch;
    stable_radix_sort(v, [](float x) {
        const auto b = std::bit_cast<std::uint32_t>(x);
        return (b & 0x80000000u) != 0 ? ~b : b | 0x80000000u;
    }, scratch);
}

// The histogram's counts over its whole range (empty bins too): bin b holds [lo + b·width, lo + (b+1)·width).
struct DenseHistogram {
    std::vector<double> counts;
    double lo = 0.0, width = 1.0;
};

// Non-empty bins of the values between the options' quantiles (and, in `dense`, all of them).
std::vector<Bin> histogram(std::span<const float> values, const TissueModelOptions& o, std::size_t& used, DenseHistogram* dense = nullptr) {
    LargeVector<float> v(values.begin(), values.end());
    sort_values(v);
    const double lo = quantile_sorted(v, o.low_quantile), hi = quantile_sorted(v, o.high_quantile);
    if (!(hi > lo)) throw std::invalid_argument("the region's intensities are flat: no tissue classes to model");
    std::vector<double> n(static_cast<std::size_t>(o.bins), 0.0), s(n), s2(n);
    const double scale = o.bins / (hi - lo);
    used = 0;
    for (const float x : v) {
        if (x < lo || x > hi) continue;
        const auto b = std::min(static_cast<std::size_t>((x - lo) * scale), n.size() - 1);
        n[b] += 1.0;
        s[b] += x;
        s2[b] += static_cast<double>(x) * x;
        ++used;
    }
    std::vector<Bin> bins;
    for (std::size_t b = 0; b < n.size(); ++b) {
        if (n[b] == 0.0) continue;
        const double m = s[b] / n[b];
        bins.push_back({n[b], m, std::max(0.0, s2[b] / n[b] - m * m)});
    }
    if (dense) *dense = {std::move(n), lo, (hi - lo) / o.bins};
    return bins;
}

// The histogram smoothed by a Gaussian of max(3 bins, 1 % of the range) (it fills the comb an
// integer image rescaled leaves): what peak_sigma reads, once for all classes.
struct SmoothedHistogram {
    std::vector<double> d;
    double lo = 0.0, width = 1.0, sigma_bins = 3.0;
};

SmoothedHistogram smoothed(const DenseHistogram& h) {
    const auto n = static_cast<std::ptrdiff_t>(h.counts.size());
    const double s = std::max(3.0, 0.01 * static_cast<double>(n));  // in bins
    const auto reach = static_cast<std::ptrdiff_t>(std::ceil(4.0 * s));
    std::vector<double> kernel(static_cast<std::size_t>(2 * reach + 1));
    for (std::ptrdiff_t k = -reach; k <= reach; ++k) kernel[static_cast<std::size_t>(k + reach)] = std::exp(-0.5 * (k / s) * (k / s));
    SmoothedHistogram out{std::vector<double>(h.counts.size(), 0.0), h.lo, h.width, s};
    for (std::ptrdiff_t b = 0; b < n; ++b)
        for (std::ptrdiff_t k = -reach; k <= reach; ++k)
            if (b + k >= 0 && b + k < n) out.d[static_cast<std::size_t>(b)] += kernel[static_cast<std::size_t>(k + reach)] * h.counts[static_cast<std::size_t>(b + k)];
    return out;
}

// TissueClass::peak_sigma of class c of `classes` on the smoothed histogram: the peak is the
// maximum within mean ± max(sigma, 2 bins) and must lie nearer c's mean than any other class's (a
// wide class does not take a narrower neighbour's peak), each side's half width at half maximum is
// taken as 1.1774 σ, and the smoothing's σ comes off in quadrature.
double peak_sigma(const SmoothedHistogram& h, const std::vector<TissueClass>& classes, std::size_t c) {
    const double mean = classes[c].mean, sigma = classes[c].sigma;
    const double inf = std::numeric_limits<double>::infinity();
    const auto n = static_cast<std::ptrdiff_t>(h.d.size());
    const auto at = [&](std::ptrdiff_t b) { return h.d[static_cast<std::size_t>(b)]; };
    const auto bin_of = [&](double x) { return static_cast<std::ptrdiff_t>(std::floor((x - h.lo) / h.width)); };
    const std::ptrdiff_t from = std::max<std::ptrdiff_t>(0, bin_of(mean - std::max(sigma, 2 * h.width)));
    const std::ptrdiff_t to = std::min<std::ptrdiff_t>(n - 1, bin_of(mean + std::max(sigma, 2 * h.width)));
    if (from >= to) return inf;
    std::ptrdiff_t p = from;
    for (std::ptrdiff_t b = from; b <= to; ++b)
        if (at(b) > at(p)) p = b;
    if (p == from || p == to) return inf;  // no peak of its own in that range
    const double x = h.lo + (static_cast<double>(p) + 0.5) * h.width;
    for (const TissueClass& other : classes)
        if (std::abs(other.mean - x) < std::abs(mean - x)) return inf;  // another class's peak
    const double half = 0.5 * at(p);
    std::ptrdiff_t l = p, r = p;
    while (l > 0 && at(l) > half) --l;
    while (r < n - 1 && at(r) > half) ++r;
    if (at(l) > half || at(r) > half) return inf;
    // Positions between bins (linear crossings, the peak at its parabola's vertex), so the width
    // follows the data continuously: a shifted or rescaled image gives the same α to rounding.
    const double curve = at(p - 1) - 2.0 * at(p) + at(p + 1);
    const double peak = static_cast<double>(p) + (curve < 0.0 ? 0.5 * (at(p - 1) - at(p + 1)) / curve : 0.0);
    const double left = static_cast<double>(l) + (half - at(l)) / (at(l + 1) - at(l));
    const double right = static_cast<double>(r) - (half - at(r)) / (at(r - 1) - at(r));
    const double hw = std::max(peak - left, right - peak) * h.width;  // the wider side
    const double g = hw / std::sqrt(2.0 * std::log(2.0)), smoothing = h.sigma_bins * h.width;
    return std::sqrt(std::max(g * g - smoothing * smoothing, h.width * h.width));
}

std::vector<std::size_t> otsu_splits(const std::vector<Bin>& bins, int k) {
    std::vector<double> counts, centres;
    for (const Bin& b : bins) {
        counts.push_back(b.count);
        centres.push_back(b.mean);
    }
    return otsu_split_bins(counts, centres, k);
}

// Moments of the bins [a, b) as a class.
TissueClass moments(const std::vector<Bin>& bins, std::size_t a, std::size_t b, double total) {
    double w = 0, s = 0, s2 = 0;
    for (std::size_t i = a; i < b; ++i) {
        w += bins[i].count;
        s += bins[i].count * bins[i].mean;
        s2 += bins[i].count * (bins[i].var + bins[i].mean * bins[i].mean);
    }
    const double m = s / w;
    return {m, std::sqrt(std::max(s2 / w - m * m, 1e-12)), w / total};
}

// Density of the partial-volume class between classes a and b (weight excluded).
double mixed_density(double x, const TissueClass& a, const TissueClass& b) {
    double sum = 0.0;
    for (int t = 0; t < kMixSteps; ++t) {
        const double f = (t + 0.5) / kMixSteps;
        sum += gauss(x, (1 - f) * a.mean + f * b.mean, std::sqrt((1 - f) * a.sigma * a.sigma + f * b.sigma * b.sigma));
    }
    return sum / kMixSteps;
}

// One EM iteration over the bins; returns the mean log-likelihood per voxel before the update.
double em_step(const std::vector<Bin>& bins, double total, double var_floor, bool pv, TissueModel& m) {
    const std::size_t k = m.classes.size();
    std::vector<double> r(k, 0.0), s(k, 0.0), s2(k, 0.0), mix(k - 1, 0.0), p(k), q(k - 1);
    double ll = 0.0;
    for (const Bin& bin : bins) {
        double sum = 0.0;
        for (std::size_t c = 0; c < k; ++c) sum += p[c] = m.classes[c].weight * gauss(bin.mean, m.classes[c].mean, m.classes[c].sigma);
        for (std::size_t c = 0; pv && c + 1 < k; ++c)
            sum += q[c] = m.mixed[c] * mixed_density(bin.mean, m.classes[c], m.classes[c + 1]);
        sum = std::max(sum, 1e-300);
        ll += bin.count * std::log(sum);
        for (std::size_t c = 0; c < k; ++c) {
            const double g = bin.count * p[c] / sum;
            r[c] += g;
            s[c] += g * bin.mean;
            s2[c] += g * (bin.var + bin.mean * bin.mean);
        }
        for (std::size_t c = 0; pv && c + 1 < k; ++c) mix[c] += bin.count * q[c] / sum;
    }
    for (std::size_t c = 0; c < k; ++c) {
        TissueClass& t = m.classes[c];
        t.weight = r[c] / total;
        if (r[c] <= 0) continue;
        t.mean = s[c] / r[c];
        t.sigma = std::sqrt(std::max(s2[c] / r[c] - t.mean * t.mean, var_floor));
    }
    for (std::size_t c = 0; pv && c + 1 < k; ++c) m.mixed[c] = mix[c] / total;
    return ll / total;
}

// EM iterations from the model's current state until the log-likelihood settles.
void run_em(const std::vector<Bin>& bins, double total, double var_floor, bool pv, const TissueModelOptions& o,
            TissueModel& m) {
    double previous = -1e300;
    m.converged = false;
    for (m.iterations = 1; m.iterations <= o.max_iterations; ++m.iterations) {
        m.log_likelihood = em_step(bins, total, var_floor, pv, m);
        if (std::abs(m.log_likelihood - previous) <= o.tolerance) {
            m.converged = true;
            break;
        }
        previous = m.log_likelihood;
    }
    m.iterations = std::min(m.iterations, o.max_iterations);
    std::sort(m.classes.begin(), m.classes.end(), [](const TissueClass& x, const TissueClass& y) { return x.mean < y.mean; });
}

// The share of the region class c makes: its pure voxels and half of the partial-volume voxels
// it shares with each neighbour. A tissue seen mostly mixed (a PD's CSF in a brain mask that keeps
// little of it pure: 0.96 % pure, 25 % mixed with grey matter) is there all the same; its mean is
// pinned by the mixed voxels, which lie between it and its neighbour. A class with (almost) no
// pure voxels is not: noise at σ 14 on a T1 gave a fit whose CSF held 0.0 % pure and 8.5 % by
// mixture, its mean at 21 ± 0.3 (kMinPure).
double presence(const TissueModel& m, std::size_t c) {
    double p = m.classes[c].weight;
    if (c > 0 && c - 1 < m.mixed.size()) p += 0.5 * m.mixed[c - 1];
    if (c < m.mixed.size()) p += 0.5 * m.mixed[c];
    return p;
}

// Why a fitted model cannot be used, or "".
std::string degeneracy(const TissueModel& m) {
    std::ostringstream os;
    for (std::size_t c = 0; c < m.classes.size(); ++c) {
        const bool present = presence(m, c) >= 0.01;
        if (!present || !(m.classes[c].weight >= kMinPure) || !std::isfinite(m.classes[c].mean)) {
            os << "tissue class " << c + 1 << " of " << m.classes.size()
               << (present ? " holds under 0.5 % of the voxels pure" : " holds under 1 % of the voxels");
            return os.str();
        }
    }
    for (std::size_t c = 0; c + 1 < m.classes.size(); ++c) {
        const TissueClass &a = m.classes[c], &b = m.classes[c + 1];
        // Two Gaussians of equal spread σ make two modes only when their means lie over 2σ apart;
        // closer, the "classes" are pieces of one tissue. With unequal spreads the narrower class
        // stands out of the wider one when its mean lies over two of its own spreads from the other's
        // (GM against a WM widened by a strong bias field).
        if (b.mean - a.mean < 2.0 * std::min(a.sigma, b.sigma)) {
            os << "tissue classes " << c + 1 << " and " << c + 2 << " overlap (means " << a.mean << " and " << b.mean
               << " less than two spreads apart)";
            return os.str();
        }
    }
    return {};
}

// The classes the bins split at `splits` (k − 1 ascending indices) give, as moments.
TissueModel split_start(const std::vector<Bin>& bins, const std::vector<std::size_t>& splits, double total) {
    TissueModel m;
    std::size_t a = 0;
    for (std::size_t c = 0; c <= splits.size(); ++c) {
        const std::size_t b = c < splits.size() ? splits[c] : bins.size();
        m.classes.push_back(moments(bins, a, b, total));
        a = b;
    }
    m.mixed.assign(splits.size(), 0.0);
    return m;
}

// EM from `start`: with `plain_first` a plain Gaussian mixture, then the partial-volume classes
// started from it; else the partial-volume classes at once (the plain mixture only when they
// fail). A partial-volume fit that is not sound gives way to the plain mixture, with a note.
TissueModel fit_from(const std::vector<Bin>& bins, const TissueModel& start, bool plain_first, double total, double var_floor,
                     const TissueModelOptions& o) {
    const auto plain = [&] {
        TissueModel m = start;
        run_em(bins, total, var_floor, false, o, m);
        return m;
    };
    if (!o.partial_volume) return plain();
    TissueModel m = plain_first ? plain() : start;
    if (plain_first && !degeneracy(m).empty()) return m;
    TissueModel pv = m;
    pv.mixed.assign(m.mixed.size(), 0.1);
    for (TissueClass& c : pv.classes) c.weight *= 1.0 - 0.1 * static_cast<double>(m.mixed.size());
    run_em(bins, total, var_floor, true, o, pv);
    if (plain_first) pv.iterations += m.iterations;
    if (const std::string why = degeneracy(pv); why.empty()) return pv;
    if (!plain_first) m = plain();
    m.note = "the partial-volume fit failed (" + degeneracy(pv) + "): plain mixture used";
    return m;
}

// A start at the `k` most prominent peaks of the smoothed histogram: each class's mean at its peak,
// its σ the peak's width (peak_sigma; one bin where it has none), its weight the share of the bins
// between the lowest points that part it from its neighbours. None when fewer peaks stand over 1 % of
// the tallest (a peak's prominence: its height above the higher of the two lowest points that part it
// from a taller peak, or from the histogram's end).
std::optional<TissueModel> peak_start(const SmoothedHistogram& h, const std::vector<Bin>& bins, int k, double total) {
    const std::vector<double>& d = h.d;
    const std::size_t n = d.size();
    const double tallest = *std::max_element(d.begin(), d.end());
    std::vector<std::pair<double, std::size_t>> peaks;  // (prominence, bin)
    for (std::size_t p = 0; p < n; ++p) {
        if ((p > 0 && !(d[p] > d[p - 1])) || (p + 1 < n && d[p + 1] > d[p])) continue;
        double left = d[p], right = d[p];
        for (std::size_t i = p; i-- > 0 && d[i] <= d[p];) left = std::min(left, d[i]);
        for (std::size_t i = p + 1; i < n && d[i] <= d[p]; ++i) right = std::min(right, d[i]);
        if (const double prominence = d[p] - std::max(left, right); prominence >= 0.01 * tallest) peaks.emplace_back(prominence, p);
    }
    if (peaks.size() < static_cast<std::size_t>(k)) return std::nullopt;
    std::sort(peaks.begin(), peaks.end(), [](const auto& x, const auto& y) { return x.first > y.first || (x.first == y.first && x.second < y.second); });
    std::vector<std::size_t> at;
    for (int i = 0; i < k; ++i) at.push_back(peaks[static_cast<std::size_t>(i)].second);
    std::sort(at.begin(), at.end());
    std::vector<std::size_t> splits;
    for (std::size_t i = 0; i + 1 < at.size(); ++i) {
        std::size_t v = at[i];
        for (std::size_t b = at[i]; b <= at[i + 1]; ++b)
            if (d[b] < d[v]) v = b;
        const double x = h.lo + static_cast<double>(v) * h.width;  // the valley bin's lower edge
        const auto first = static_cast<std::size_t>(std::lower_bound(bins.begin(), bins.end(), x, [](const Bin& b, double t) { return b.mean < t; }) - bins.begin());
        if (first == 0 || first >= bins.size() || (!splits.empty() && first <= splits.back())) return std::nullopt;
        splits.push_back(first);
    }
    TissueModel m = split_start(bins, splits, total);
    for (std::size_t c = 0; c < at.size(); ++c) {  // each class at its peak, as wide as the peak
        m.classes[c].mean = h.lo + (static_cast<double>(at[c]) + 0.5) * h.width;
        m.classes[c].sigma = h.width;
    }
    for (std::size_t c = 0; c < at.size(); ++c)
        if (const double w = peak_sigma(h, m.classes, c); std::isfinite(w)) m.classes[c].sigma = w;
    return m;
}

}  // namespace

// Multi-level Otsu by dynamic programming: splits the bins into `k` runs maximising the
// between-class variance (Σ S1²/S0 over the runs; the first maximum in bin order wins).
std::vector<std::size_t> otsu_split_bins(std::span<const double> counts, std::span<const double> centres, int k) {
    const std::size_t n = counts.size();
    if (k < 2 || centres.size() != n || n < static_cast<std::size_t>(k))
        throw std::invalid_argument("Otsu thresholds need at least as many bins as classes (and 2 classes or more)");
    std::vector<double> c0(n + 1, 0.0), c1(n + 1, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
        c0[i + 1] = c0[i] + counts[i];
        c1[i + 1] = c1[i] + counts[i] * centres[i];
    }
    const auto run = [&](std::size_t a, std::size_t b) {  // bins [a, b)
        const double w = c0[b] - c0[a], s = c1[b] - c1[a];
        return w > 0 ? s * s / w : 0.0;
    };
    const double none = -1.0;
    // best[j][i]: best value splitting bins [0, i) into j + 1 runs; from[j][i]: start of the last.
    std::vector<std::vector<double>> best(static_cast<std::size_t>(k), std::vector<double>(n + 1, none));
    std::vector<std::vector<std::size_t>> from(best.size(), std::vector<std::size_t>(n + 1, 0));
    for (std::size_t i = 1; i <= n; ++i) best[0][i] = run(0, i);
    for (std::size_t j = 1; j < best.size(); ++j)
        for (std::size_t i = j + 1; i <= n; ++i)
            for (std::size_t a = j; a < i; ++a) {
                if (best[j - 1][a] == none) continue;
                const double v = best[j - 1][a] + run(a, i);
                if (v > best[j][i]) {
                    best[j][i] = v;
                    from[j][i] = a;
                }
            }
    std::vector<std::size_t> splits(static_cast<std::size_t>(k - 1));
    std::size_t end = n;
    for (std::size_t j = best.size() - 1; j >= 1; --j) {
        end = from[j][end];
        splits[j - 1] = end;
    }
    return splits;
}

void TissueModelOptions::validate() const {
    if (classes < 2 || classes > 6) throw std::invalid_argument("the tissue model needs 2 to 6 classes");
    if (bins < 32 || bins > 65536) throw std::invalid_argument("the tissue model's histogram needs 32 to 65536 bins");
    if (!(low_quantile >= 0.0 && high_quantile <= 1.0 && low_quantile < high_quantile))
        throw std::invalid_argument("the tissue model's quantiles must satisfy 0 <= low < high <= 1");
    if (max_iterations < 1) throw std::invalid_argument("the tissue model needs at least one EM iteration");
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) throw std::invalid_argument("the EM tolerance must be finite and >= 0");
}

int TissueModel::classify(double value) const {
    int best = 0;
    double top = -1.0;
    for (std::size_t c = 0; c < classes.size(); ++c) {
        const double p = classes[c].weight * gauss(value, classes[c].mean, classes[c].sigma);
        if (p > top) {
            top = p;
            best = static_cast<int>(c);
        }
    }
    return best;
}

double TissueModel::density(double value) const {
    double sum = 0.0;
    for (const TissueClass& c : classes) sum += c.weight * gauss(value, c.mean, c.sigma);
    for (std::size_t c = 0; c < mixed.size(); ++c) sum += mixed[c] * mixed_density(value, classes[c], classes[c + 1]);
    return sum;
}

TissueModel fit_tissue_model(std::span<const float> values, const TissueModelOptions& o) {
    o.validate();
    if (values.empty()) throw std::invalid_argument("the tissue model has no voxels to fit");
    for (const float x : values)
        if (!std::isfinite(x)) throw std::invalid_argument("image has non-finite voxels");
    std::size_t used = 0;
    DenseHistogram dense;
    const std::vector<Bin> bins = histogram(values, o, used, &dense);
    if (bins.size() < static_cast<std::size_t>(2 * o.classes)) {
        std::ostringstream os;
        os << "the region has " << bins.size() << " distinct intensity levels: too few for " << o.classes << " tissue classes";
        throw std::invalid_argument(os.str());
    }
    const double total = static_cast<double>(used);
    const double width = (bins.back().mean - bins.front().mean) / o.bins;
    const double var_floor = std::max(width * width, 1e-12);
    const SmoothedHistogram smooth = smoothed(dense);
    // Two starts: Otsu's splits, and the histogram's most prominent peaks. Otsu balances the classes'
    // variance; where one tissue lies far from the others (a T2's CSF, bright and spread by partial
    // volume) it spends a split on that tail and starts two tissues as one, which the EM does not
    // part again. The peak start's fit is kept where it is sound and clearly more likely (a T2's
    // brain: +0.038 nats per voxel); near-equal optima (a noisy T1: ±0.0001, means a unit apart) keep
    // Otsu's, as before.
    // The two fits are independent (each a serial EM over the bins): run side by side.
    const std::optional<TissueModel> peaks = peak_start(smooth, bins, o.classes, total);
    TissueModel m, other;
    tbb::parallel_invoke([&] { m = fit_from(bins, split_start(bins, otsu_splits(bins, o.classes), total), true, total, var_floor, o); },
                         [&] {
                             if (peaks) other = fit_from(bins, *peaks, false, total, var_floor, o);
                         });
    if (peaks) {
        // Each class a peak of its own, as it was started, and no narrower than the histogram's
        // smoothing: a spike is a value an intensity normalisation pinned (FreeSurfer's white matter
        // at 110), whose likelihood would outweigh every tissue's (BrainWeb so pinned with Rician
        // noise σ 9: a class of σ 0.9 at the pin, the seeds' class CSF, GM Dice 0.92 → 0.78).
        bool peaked = degeneracy(other).empty() && other.note.empty();  // its partial-volume fit sound too
        for (std::size_t c = 0; peaked && c < other.classes.size(); ++c)
            peaked = other.classes[c].sigma >= smooth.sigma_bins * smooth.width && std::isfinite(peak_sigma(smooth, other.classes, c));
        if (peaked && (!degeneracy(m).empty() || other.log_likelihood > m.log_likelihood + kClearlyMoreLikely)) {
            m = std::move(other);
            m.start = "peaks";
        }
    }
    m.voxels = used;
    m.degenerate = degeneracy(m);
    for (std::size_t c = 0; c < m.classes.size(); ++c) m.classes[c].peak_sigma = peak_sigma(smooth, m.classes, c);
    return m;
}

TissueModel fit_tissue_model(const Grid<float>& image, const Grid<std::uint8_t>* region, const TissueModelOptions& o) {
    if (region && !(region->dims() == image.dims())) {
        std::ostringstream os;
        os << "tissue-model region " << region->dims() << " does not match the image " << image.dims();
        throw std::invalid_argument(os.str());
    }
    LargeVector<float> v;
    v.reserve(image.size());
    const std::span<const float> values = image.values();
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!region || (*region)[static_cast<PointIndex>(i)] != 0) v.push_back(values[i]);
    if (v.empty()) throw std::invalid_argument("the tissue model's region holds no voxel");
    // A skull-stripped or masked image holds its background at one value, its minimum, often inside
    // the region too (between gyri, in the ventricles): a spike no tissue makes. Left out when it
    // is at least 1 % of the region.
    const float low = *std::min_element(values.begin(), values.end());
    const auto at_low = static_cast<std::size_t>(std::count(v.begin(), v.end(), low));
    if (at_low * 100 >= v.size() && at_low < v.size()) std::erase(v, low);
    return fit_tissue_model(std::span<const float>(v), o);
}

std::vector<double> otsu_thresholds(std::span<const float> values, int classes, int bins) {
    TissueModelOptions o;
    o.classes = classes;
    o.bins = bins;
    o.validate();
    for (const float x : values)
        if (!std::isfinite(x)) throw std::invalid_argument("image has non-finite voxels");
    std::size_t used = 0;
    const std::vector<Bin> h = histogram(values, o, used);
    if (h.size() < static_cast<std::size_t>(classes)) throw std::invalid_argument("too few intensity levels to threshold");
    std::vector<double> t;
    for (const std::size_t s : otsu_splits(h, classes)) t.push_back(0.5 * (h[s - 1].mean + h[s].mean));
    return t;
}

const char* to_string(TissueContrast contrast) {
    switch (contrast) {
        case TissueContrast::kT1: return "T1";
        case TissueContrast::kGreyBrighter: return "grey brighter than white (T2, PD)";
    }
    return "?";
}

std::string tissue_class_name(const TissueModel& model, int k) {
    if (model.classes.size() == 3 && k >= 0 && k < 3) {
        static const char* const t1[] = {"CSF", "GM", "WM"};
        switch (model.contrast.value_or(TissueContrast::kT1)) {
            case TissueContrast::kT1: return t1[k];
            case TissueContrast::kGreyBrighter: return t1[2 - k];
        }
    }
    return "class " + std::to_string(k + 1);
}

ModelWindow model_window(const TissueModel& m, std::span<const float> seed_values) {
    if (!m.usable()) throw std::invalid_argument("the tissue model is not usable: " + m.degenerate);
    if (seed_values.empty()) throw std::invalid_argument("the seeds cover no voxel");
    const std::size_t k = m.classes.size();
    std::vector<std::size_t> votes(k, 0);
    for (const float x : seed_values) ++votes[static_cast<std::size_t>(m.classify(x))];
    ModelWindow w;
    const auto top = std::max_element(votes.begin(), votes.end());
    w.seed_class = static_cast<int>(top - votes.begin());
    w.seed_class_share = static_cast<double>(*top) / static_cast<double>(seed_values.size());
    const auto c = static_cast<std::size_t>(w.seed_class);
    const TissueClass& t = m.classes[c];
    const double lower = c > 0 ? 0.5 * (m.classes[c - 1].mean + t.mean) : 0.0;
    const double upper = c + 1 < k ? 0.5 * (t.mean + m.classes[c + 1].mean) : 0.0;
    w.lower = c > 0 ? lower : t.mean - std::max(upper - t.mean, 3.0 * t.sigma);
    w.upper = c + 1 < k ? upper : t.mean + std::max(t.mean - lower, 3.0 * t.sigma);
    if (w.seed_class_share < 0.7) {
        std::ostringstream os;
        os << "the seeds fall in two tissue classes (" << static_cast<int>(std::lround(100 * w.seed_class_share)) << " % "
           << tissue_class_name(m, w.seed_class) << "): the window is " << tissue_class_name(m, w.seed_class)
           << "'s; move the seeds deeper into one tissue";
        w.warnings.push_back(os.str());
    }
    return w;
}

}  // namespace liveset
