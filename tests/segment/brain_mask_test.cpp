// Automatic brain mask: BrainWeb against its tissue labels (and variants built from it: intensity
// scaling, bias field, noise, 2 mm voxels, skull-stripped), an analytic head of spheres, bad input.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "liveset/io/image_io.hpp"
#include "brain_mask_fixture.hpp"
#include "noisy_phantom.hpp"
#include "liveset/segment/brain_histogram.hpp"
#include "liveset/segment/voxel_loops.hpp"
#include "liveset/segment/brain_mask.hpp"
#include "liveset/segment/morphology.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/tissue_model.hpp"
#include "liveset/segment/window.hpp"

using namespace liveset;
using namespace liveset::bm_test;

namespace {

enum class Variant { kPlain, kScaled, kBias, kNoise, kHeavyNoise, kRician, kStripped };

// A variant of an image (the same truth holds for each); kStripped multiplies by `brain`.
Grid<float> make_variant(const Grid<float>& t1, const Mask& brain, Variant v) {
    Grid<float> out = t1;
    const Vec3i d = t1.dims();
    std::mt19937 rng(12345);
    std::normal_distribution<float> noise(0.0f, 8.0f);  // ~6 % of white matter
    std::normal_distribution<float> heavy(0.0f, 12.0f);  // ~9 % of white matter: BrainWeb's noisiest
    std::normal_distribution<float> rician(0.0f, 14.0f);  // beyond it: the air's noise crosses the head threshold
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                float& o = out({x, y, z});
                const double u = 2.0 * x / (d.x - 1) - 1, w = 2.0 * y / (d.y - 1) - 1, s = 2.0 * z / (d.z - 1) - 1;
                switch (v) {
                    case Variant::kPlain: break;
                    case Variant::kScaled: o = 7.3f * o + 250.0f; break;
                    case Variant::kBias:  // smooth multiplicative field within ±20 %
                        o *= static_cast<float>(1.0 + 0.2 * std::sin(1.3 * u + 0.4) * std::cos(1.1 * w - 0.3) * std::cos(0.9 * s + 0.2));
                        break;
                    case Variant::kNoise: o += noise(rng); break;
                    case Variant::kHeavyNoise: o = std::abs(o + heavy(rng)); break;  // magnitude
                    case Variant::kRician: o = std::hypot(o + rician(rng), rician(rng)); break;
                    case Variant::kStripped: o = brain({x, y, z}) != 0 ? o : 0.0f; break;
                }
            }
    return out;
}

double dice(const Mask& a, const Mask& b) {
    std::size_t na = 0, nb = 0, both = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const bool x = a[static_cast<PointIndex>(i)] != 0, y = b[static_cast<PointIndex>(i)] != 0;
        na += x;
        nb += y;
        both += x && y;
    }
    return 2.0 * double(both) / double(na + nb);
}

// A full head (stripped_with == nullptr) or the image cut with `stripped_with`, whose non-zero brain
// the mask must then cover whole. `leak_bound`: the share of non-brain voxels in the GM window
// allowed inside (noisy images: more, as the smoothed tissue test lets the mask follow the cortex).
TruthCheck run_variant(const char* name, const Grid<float>& image, const Mask& labels, const Mask* stripped_with = nullptr,
                       double leak_bound = 0.015, BrainMaskReport* report = nullptr) {
    const bool expect_stripped = stripped_with != nullptr;
    BrainMaskReport local;
    BrainMaskReport& r = report != nullptr ? *report : local;
    const auto t0 = std::chrono::steady_clock::now();
    const Mask mask = auto_brain_mask(image, {}, &r);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const TruthCheck c = check_against_truth(mask, labels, image);
    std::printf("%-9s dice %.4f  GM in %.4f  WM in %.4f  scalp/muscle/skin/fat in %.4f  GM-window leak %.4f  "
                "(window %.1f..%.1f, contact %.2f, stripped %d, %.0f %% of the head, %.1f s)\n",
                name, c.dice, c.gm, c.wm, c.extracranial, c.leak, r.tissue_low, r.tissue_high, r.surface_contact,
                int(r.skull_stripped), 100.0 * double(r.mask_voxels) / double(r.head_voxels), s);
    EXPECT_EQ(r.skull_stripped, expect_stripped) << name << ": surface contact " << r.surface_contact;
    EXPECT_EQ(r.contrast, TissueContrast::kT1) << name << ": deep skew " << r.deep_skew;  // every variant here is a T1
    EXPECT_EQ(brain_contrast(image, mask), TissueContrast::kT1) << name;  // and so is the brain it found, read alone
    if (expect_stripped) {  // the truth is the non-zero brain (brain_mask.nii.gz also keeps some non-brain)
        Mask nonzero(image.lattice());
        for (std::size_t i = 0; i < image.size(); ++i) nonzero[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] != 0;
        const double d = dice(mask, nonzero);
        std::printf("%-9s dice against the non-zero brain %.4f\n", name, d);
        EXPECT_GE(d, 0.995) << name;
    }
    EXPECT_GE(c.gm, 0.99) << name;
    EXPECT_GE(c.wm, 0.998) << name;
    if (!expect_stripped) {
        EXPECT_GE(c.dice, 0.95) << name;
        EXPECT_LE(c.extracranial, 0.03) << name;
        EXPECT_LE(c.leak, leak_bound) << name;
    }
    EXPECT_EQ(r.mask_voxels, static_cast<std::size_t>(std::count(mask.values().begin(), mask.values().end(), 1)));
    return c;
}

}  // namespace

TEST(BrainMask, BrainWebFullHeadMatchesBrainTissue) {
    const BrainWeb& bw = brainweb();
    run_variant("1mm", bw.t1, bw.labels);
}

// BrainWeb defaced as public datasets are (pydeface, mri_deface): everything but the brain and 3 mm
// around it zeroed in a wedge in front of and below the frontal lobe - eyes, nose, mouth, chin. The
// cut exposes 9-12 % of the brain's boundary within 4 mm of the surface, which a skull-stripped
// detection at 10 % took for a stripped brain (mask Dice 0.50 against the brain, GM 0.54): it is a
// full head, masked as one.
TEST(BrainMask, ADefacedHeadIsAFullHead) {
    const BrainWeb& bw = brainweb();
    const Lattice& l = bw.t1.lattice();
    Mask brain(l);
    double y_front = 1e300, z_low = 1e300, z_high = -1e300;
    for (PointIndex i = 0; i < brain.size(); ++i) {
        brain[i] = brain_label(bw.labels[i]);
        if (!brain[i]) continue;
        const Vec3d w = l.to_world(l.coord(i).cast<double>());
        y_front = std::min(y_front, w.y), z_low = std::min(z_low, w.z), z_high = std::max(z_high, w.z);
    }
    const Mask kept = dilate_mm(brain, 3.0);
    const double z_cut = z_low + 0.35 * (z_high - z_low) + 10.0;  // LPS: anterior is -y, inferior -z
    Grid<float> defaced = bw.t1;
    std::size_t cut = 0;
    for (PointIndex i = 0; i < defaced.size(); ++i) {
        const Vec3d w = l.to_world(l.coord(i).cast<double>());
        if (!kept[i] && w.z < z_cut && w.y < y_front + 1.2 * (z_cut - w.z)) defaced[i] = 0.0f, ++cut;
    }
    ASSERT_GT(cut, 300000u);  // the face is gone (BrainWeb: 0.63 M voxels)
    BrainMaskReport r;
    run_variant("defaced", defaced, bw.labels, nullptr, 0.015, &r);
    EXPECT_GT(r.surface_contact, 0.05);  // the cut does reach the brain
}

TEST(BrainMask, BrainWebSkullStrippedPassesThrough) {
    const BrainWeb& bw = brainweb();
    run_variant("stripped", make_variant(bw.t1, bw.brain_mask, Variant::kStripped), bw.labels, &bw.brain_mask);
}

// Noise at BrainWeb's harshest (σ 12, ~9 % of white matter) at 1 mm: the tissue test on the
// smoothed image keeps the cortex inside (without the smoothing 88 % of GM was, Dice 0.81 → 0.87
// for a GM segmentation inside it).
TEST(BrainMask, HeavyNoiseKeepsTheCortexInside) {
    const BrainWeb& bw = brainweb();
    run_variant("noise12", make_variant(bw.t1, bw.brain_mask, Variant::kHeavyNoise), bw.labels, nullptr, 0.025);
}

// Rician noise σ 14 (BrainWeb's own ~4 on top: 14.6 in all): a third of the air lies above the head
// threshold p2 + 10 % (p98 − p2), which without the background's noise level made the whole field of
// view "head" and the brain mask a 5 % fragment ("no brain found"); at floor + 2σ it is the head.
TEST(BrainMask, HeavyRicianNoiseRaisesTheHeadThresholdToTheAirsNoise) {
    const BrainWeb& bw = brainweb();
    const Grid<float> noisy = make_variant(bw.t1, bw.brain_mask, Variant::kRician);
    BrainMaskReport r;
    run_variant("rician14", noisy, bw.labels, nullptr, 0.03, &r);
    EXPECT_NEAR(r.background_noise, std::hypot(14.0, 4.0), 0.07 * 14.6);
    EXPECT_GE(r.head_threshold, 2 * r.background_noise);
    EXPECT_GT(r.head_threshold, r.background_threshold);
    BrainMaskOptions without;
    without.noise_multiple = 0;
    EXPECT_THROW(auto_brain_mask(noisy, without), NoBrainFound);  // the last look too: its deep head is skewed bright
}

// The background threshold is p2 + 10 % (p98 − p2) of the voxels' values, p98 taken among those
// above p2, each the element at floor(q·(n − 1)) of the sorted values (the selection by a histogram
// of the values' bits must give exactly that element), on BrainWeb and on its 2 mm version with
// negative values and ties (an offset, then rounding to integers) and with hardly any tie.
TEST(BrainMask, BackgroundThresholdIsTheDocumentedPercentileRule) {
    const Grid<float> t1 = every_other(brainweb().t1);
    Grid<float> rounded = t1, distinct = t1;
    for (float& v : rounded.values()) v = std::round(v - 20.0f);
    for (std::size_t i = 0; i < distinct.size(); ++i) distinct[static_cast<PointIndex>(i)] += static_cast<float>(i % 9973) * 1e-4f;
    for (const Grid<float>* image : {&brainweb().t1, &t1, static_cast<const Grid<float>*>(&rounded), static_cast<const Grid<float>*>(&distinct)}) {
        std::vector<float> sorted(image->values().begin(), image->values().end());
        std::sort(sorted.begin(), sorted.end());
        const auto at = [](const std::vector<float>& v, double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]; };
        const double p2 = at(sorted, 0.02);
        const std::vector<float> above(std::upper_bound(sorted.begin(), sorted.end(), static_cast<float>(p2)), sorted.end());
        const double p98 = at(above, 0.98);
        BrainMaskReport r;
        auto_brain_mask(*image, {}, &r);
        EXPECT_DOUBLE_EQ(r.background_threshold, p2 + 0.1 * (p98 - p2));
    }
}

// The brain mask's quantile (brain_histogram.hpp) against a sort of the kept values in the order
// of their bits (−0 before +0): fractions from 0 to 1, inside a mask and not, above several floors
// (NaN never kept), on an image with repeated values, ±0 and NaN; and none when nothing lies above.
TEST(BrainMask, QuantileAboveIsTheSortedKeptValue) {
    const Lattice lat({80, 70, 60});
    Grid<float> image(lat, 0.0f);
    Grid<std::uint8_t> mask(lat, 0);
    std::mt19937 rng(73);
    std::normal_distribution<float> value(40.0f, 30.0f);
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        const unsigned r = rng() % 100;
        image[p] = r < 3 ? -0.0f : r < 6 ? 0.0f : r < 7 ? std::numeric_limits<float>::quiet_NaN() : r < 40 ? std::round(value(rng)) : value(rng);
        mask[p] = rng() % 3 != 0;
    }
    const auto bits = [](float v) {
        const auto u = std::bit_cast<std::uint32_t>(v);
        return (u & 0x80000000u) != 0 ? ~u : (u | 0x80000000u);
    };
    for (const bool masked : {false, true})
        for (const double above : {-std::numeric_limits<double>::infinity(), -0.5, 0.0, 40.0}) {
            std::vector<float> kept;
            for (std::size_t i = 0; i < image.size(); ++i) {
                const float v = image[static_cast<PointIndex>(i)];
                if ((!masked || mask[static_cast<PointIndex>(i)] != 0) && static_cast<double>(v) > above) kept.push_back(v);
            }
            std::sort(kept.begin(), kept.end(), [&](float a, float b) { return bits(a) < bits(b); });
            ASSERT_GT(kept.size(), 1000u);
            const std::vector<double> fractions{0.0, 0.001, 0.02, 0.1, 0.5, 0.9, 0.98, 0.995, 1.0, 0.5, 0.37};
            for (const int threads : {1, 3}) {  // all at once, a fraction twice: the same values
                std::vector<float> all;
                tbb::task_arena(threads).execute([&] { all = brain_detail::quantiles_above(image, masked ? &mask : nullptr, above, fractions); });
                ASSERT_EQ(all.size(), fractions.size());
                for (std::size_t f = 0; f < fractions.size(); ++f)
                    EXPECT_EQ(std::bit_cast<std::uint32_t>(all[f]),
                              std::bit_cast<std::uint32_t>(kept[static_cast<std::size_t>(fractions[f] * static_cast<double>(kept.size() - 1))]))
                        << "fraction " << fractions[f] << " above " << above << (masked ? " masked" : "") << " threads " << threads;
            }
            for (const double q : {0.0, 0.001, 0.02, 0.1, 0.5, 0.9, 0.98, 0.995, 1.0}) {
                const float want = kept[static_cast<std::size_t>(q * static_cast<double>(kept.size() - 1))];
                for (const int threads : {1, 3}) {  // blocks counted and gathered on any thread
                    std::optional<float> got;
                    tbb::task_arena(threads).execute([&] { got = brain_detail::quantile_above(image, masked ? &mask : nullptr, above, q); });
                    ASSERT_TRUE(got);
                    EXPECT_EQ(std::bit_cast<std::uint32_t>(*got), std::bit_cast<std::uint32_t>(want))
                        << "q " << q << " above " << above << (masked ? " masked" : "") << " threads " << threads;
                }
            }
        }
    EXPECT_FALSE(brain_detail::quantile_above(image, nullptr, 1e9, 0.5));
    EXPECT_TRUE(brain_detail::quantiles_above(image, nullptr, 1e9, std::vector<double>{0.1, 0.5}).empty());
}

TEST(BrainMask, BrainWebVariantsAt2mm) {
    const BrainWeb& bw = brainweb();
    const Grid<float> t1 = every_other(bw.t1);
    const Mask labels = every_other(bw.labels), brain = every_other(bw.brain_mask);
    run_variant("2mm", t1, labels);
    run_variant("scaled", make_variant(t1, brain, Variant::kScaled), labels);
    run_variant("bias", make_variant(t1, brain, Variant::kBias), labels);
    run_variant("noise", make_variant(t1, brain, Variant::kNoise), labels, nullptr, 0.025);
    run_variant("strip2mm", make_variant(t1, brain, Variant::kStripped), labels, &brain);
}

// The head a mask was found in, given back: the same mask on the same image (nothing else is
// reused); on that image under a ±20 % field, the brain found in the given head is a brain mask as
// good against the truth as the one found from scratch, and the head's depth is the one that
// image's own head has; a head of another size is refused.
TEST(BrainMask, FoundAgainInTheHeadItWasFirstFoundIn) {
    const BrainWeb& bw = brainweb();
    const Grid<float> t1 = every_other(bw.t1);
    const Mask labels = every_other(bw.labels), brain = every_other(bw.brain_mask);
    BrainMaskHead head;
    BrainMaskReport first;
    const Mask plain = auto_brain_mask(t1, {}, &first, &head);
    ASSERT_TRUE(head.solid.dims() == t1.dims());
    ASSERT_TRUE(head.depth.dims() == t1.dims());
    EXPECT_EQ(static_cast<std::size_t>(std::count(head.solid.values().begin(), head.solid.values().end(), 1)),
              first.head_voxels + first.below_voxels);
    const BrainMaskHead kept = head;
    BrainMaskReport again;
    const Mask same = auto_brain_mask(t1, {}, &again, &head);
    EXPECT_TRUE(std::equal(plain.values().begin(), plain.values().end(), same.values().begin()));
    EXPECT_TRUE(std::equal(head.solid.values().begin(), head.solid.values().end(), kept.solid.values().begin()));  // not replaced
    EXPECT_EQ(again.head_voxels, first.head_voxels);

    const Grid<float> shaded = make_variant(t1, brain, Variant::kBias);
    BrainMaskHead own;
    const Mask scratch = auto_brain_mask(shaded, {}, nullptr, &own);
    const Mask reused = auto_brain_mask(shaded, {}, nullptr, &head);
    const auto dice = [&](const Mask& m) {
        std::size_t a = 0, b = 0, both = 0;
        for (PointIndex i = 0; i < m.size(); ++i) {
            const bool t = brain_label(labels[i]);
            a += m[i] != 0, b += t, both += m[i] != 0 && t;
        }
        return 2.0 * static_cast<double>(both) / static_cast<double>(a + b);
    };
    std::printf("±20 %% field: brain Dice from scratch %.4f, in the first head %.4f\n", dice(scratch), dice(reused));
    EXPECT_GT(dice(reused), dice(scratch) - 0.002);
    std::size_t differ = 0;
    for (PointIndex i = 0; i < own.solid.size(); ++i) differ += own.solid[i] != head.solid[i];
    EXPECT_LT(static_cast<double>(differ), 0.005 * static_cast<double>(first.head_voxels));

    BrainMaskHead wrong;
    wrong.solid = Mask(Lattice({3, 3, 3}));
    wrong.depth = Grid<float>(Lattice({3, 3, 3}));
    EXPECT_THROW(auto_brain_mask(t1, {}, nullptr, &wrong), std::invalid_argument);
}

TEST(BrainMask, SameMaskWhateverTheThreadCount) {
    const Grid<float> t1 = every_other(brainweb().t1);
    const Mask many = auto_brain_mask(t1);
    Mask one;
    {
        const tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
        one = auto_brain_mask(t1);
    }
    EXPECT_TRUE(std::equal(many.values().begin(), many.values().end(), one.values().begin()));
}

namespace {

// An analytic head on a lattice of `spacing` (mm), centred: white matter (r < 18 mm, 130), grey matter
// (< 27, 95), CSF (< 29, 45), dark skull (< 35, 8), bright scalp (< 42, 160), air (0); Gaussian
// noise σ 3 (absolute value, like magnitude MR). The brain is r < 29 mm.
float head_value(double r) { return r < 18 ? 130.0f : r < 27 ? 95.0f : r < 29 ? 45.0f : r < 35 ? 8.0f : r < 42 ? 160.0f : 0.0f; }

double radius(Vec3i p, Vec3i d, Vec3d spacing) {
    return norm(Vec3d{(p.x - (d.x - 1) / 2.0) * spacing.x, (p.y - (d.y - 1) / 2.0) * spacing.y, (p.z - (d.z - 1) / 2.0) * spacing.z});
}

Grid<float> sphere_head(Vec3d spacing, Mask* brain) {
    const Vec3i d{static_cast<int>(100 / spacing.x), static_cast<int>(100 / spacing.y), static_cast<int>(100 / spacing.z)};
    Grid<float> g(Lattice(d, spacing));
    *brain = Mask(g.lattice());
    std::mt19937 rng(7);
    std::normal_distribution<float> noise(0.0f, 3.0f);
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const double r = radius({x, y, z}, d, spacing);
                g({x, y, z}) = std::abs(head_value(r) + noise(rng));
                (*brain)({x, y, z}) = r < 29;
            }
    return g;
}

// The same head (1 mm, `side` mm wide: under 84 there is no air) as a magnitude image with Rician
// noise σ: the air is Rayleigh distributed with mode σ.
Grid<float> rician_head(double sigma, int side) {
    const Vec3i d{side, side, side};
    Grid<float> g{Lattice(d)};
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, sigma);
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                g({x, y, z}) = static_cast<float>(std::hypot(head_value(radius({x, y, z}, d, {1, 1, 1})) + noise(rng), noise(rng)));
    return g;
}

// Voxels where the two masks differ that lie more than one voxel (the largest spacing) from the
// other mask's boundary: counted by brute force over the 26-neighbourhood scaled to one voxel.
std::size_t differences_beyond_a_voxel(const Mask& a, const Mask& b) {
    std::size_t far = 0;
    const Vec3i d = a.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                if (a({x, y, z}) == b({x, y, z})) continue;
                bool near = false;  // does b take a's value within one voxel?
                for (int k = 0; k < 27 && !near; ++k) {
                    const Vec3i q{x + k % 3 - 1, y + k / 3 % 3 - 1, z + k / 9 - 1};
                    near = a.lattice().contains(q) && b(q) == a({x, y, z});
                }
                far += !near;
            }
    return far;
}

}  // namespace

TEST(BrainMask, AnalyticHeadGivesTheBrainSphereWithinAVoxel) {
    for (const Vec3d spacing : {Vec3d{1, 1, 1}, Vec3d{1, 1.5, 2}}) {
        Mask brain;
        const Grid<float> head = sphere_head(spacing, &brain);
        BrainMaskReport r;
        const Mask mask = auto_brain_mask(head, {}, &r);
        EXPECT_EQ(brain_contrast(head, mask), TissueContrast::kT1);  // the phantom's brain alone reads as a T1 too
        std::size_t differ = 0;
        for (std::size_t i = 0; i < mask.size(); ++i) differ += mask[static_cast<PointIndex>(i)] != brain[static_cast<PointIndex>(i)];
        std::printf("spacing %s: window %.1f..%.1f, brain %zu voxels, mask %zu, %zu differ, contact %.2f\n",
                    head.lattice().describe().c_str(), r.tissue_low, r.tissue_high,
                    static_cast<std::size_t>(std::count(brain.values().begin(), brain.values().end(), 1)), r.mask_voxels, differ,
                    r.surface_contact);
        EXPECT_FALSE(r.skull_stripped);
        EXPECT_GT(r.tissue_low, 45.0);  // CSF below the window, grey matter inside it
        EXPECT_LT(r.tissue_low, 95.0);
        EXPECT_EQ(differences_beyond_a_voxel(mask, brain), 0u) << spacing;
        EXPECT_EQ(differences_beyond_a_voxel(brain, mask), 0u) << spacing;
    }
}

// The air's noise level is the Rayleigh σ (its mode), within a few %, from SNR 40 to 6.5, also with
// zeros around the field of view (a resampled scan's outside: left out of the noise's histogram); a
// background without a mode above its floor (the folded Gaussian of sphere_head) or no air at all
// (a 40 mm crop of the head) gives none, and the head threshold is then p2 + 10 % (p98 − p2) alone.
TEST(BrainMask, TheAirsNoiseIsTheRayleighSigmaOrNone) {
    for (const double sigma : {3.0, 8.0, 14.0, 20.0}) {
        Grid<float> head = rician_head(sigma, 100);
        if (sigma == 14.0)  // zeros beyond 45 mm from the centre along x and y: 34 % of the lattice
            for (int z = 0; z < 100; ++z)
                for (int y = 0; y < 100; ++y)
                    for (int x = 0; x < 100; ++x)
                        if (std::abs(x - 49.5) > 40 || std::abs(y - 49.5) > 40) head({x, y, z}) = 0.0f;
        BrainMaskReport r;
        const Mask mask = auto_brain_mask(head, {}, &r);
        std::printf("Rician sigma %.0f: noise %.2f, background threshold %.2f, head threshold %.2f, head %zu voxels\n", sigma,
                    r.background_noise, r.background_threshold, r.head_threshold, r.head_voxels);
        EXPECT_NEAR(r.background_noise, sigma, 0.05 * sigma + 0.2);
        EXPECT_GE(r.head_threshold, 2 * r.background_noise);  // above the floor, itself ≥ 0
        EXPECT_LE(r.head_threshold, std::max(r.background_threshold, 2 * r.background_noise + 0.1 * sigma));
        EXPECT_NEAR(double(r.head_voxels), 4.0 / 3.0 * 3.14159265 * 42 * 42 * 42, 0.05 * 310000);  // the head, not the box
    }
    Mask brain;
    BrainMaskReport folded, cropped, plain;
    BrainMaskOptions no_raise;
    no_raise.noise_multiple = 0;
    auto_brain_mask(sphere_head({1, 1, 1}, &brain), {}, &folded);
    auto_brain_mask(sphere_head({1, 1, 1}, &brain), no_raise, &plain);
    EXPECT_EQ(folded.background_noise, 0.0);
    EXPECT_EQ(folded.head_threshold, plain.head_threshold);
    EXPECT_EQ(folded.head_threshold, folded.background_threshold);
    auto_brain_mask(rician_head(8.0, 40), {}, &cropped);
    EXPECT_EQ(cropped.background_noise, 0.0);
    EXPECT_GT(cropped.mask_voxels, 0u);
}

TEST(BrainMask, AnalyticSkullStrippedHeadIsTheWholeForeground) {
    Mask brain;
    Grid<float> head = sphere_head({1, 1, 1}, &brain);
    for (std::size_t i = 0; i < head.size(); ++i)
        if (brain[static_cast<PointIndex>(i)] == 0) head[static_cast<PointIndex>(i)] = 0.0f;
    BrainMaskReport r;
    const Mask mask = auto_brain_mask(head, {}, &r);
    EXPECT_TRUE(r.skull_stripped);
    EXPECT_EQ(r.background_noise, 0.0);  // the zeros are a constant fill, the brain no noise mode
    EXPECT_EQ(r.head_threshold, r.background_threshold);
    for (std::size_t i = 0; i < mask.size(); ++i) ASSERT_EQ(mask[static_cast<PointIndex>(i)], brain[static_cast<PointIndex>(i)]) << i;
}

// The same skull-stripped head z-scored inside its brain with the outside left at 0 (nnU-Net-style
// preprocessing): 0 then lies between CSF and grey matter, and read as it is the whole field of view
// is head. The outside is found as the faces' exact value and read as a dark background: the brain
// again, exactly. Found again in that head after N4's correction about a floor made the outside
// uneven (a gradient, the brain scaled): the same brain. Where the faces' value is the lowest
// (the plain stripped head) or no value holds most of the faces (a full head in noisy air), no
// masked outside is reported.
TEST(BrainMask, AMaskedOutsideWithinTheTissueRangeIsTheOutside) {
    Mask brain;
    const Grid<float> head = sphere_head({1, 1, 1}, &brain);
    double sum = 0, sum2 = 0, n = 0;
    for (PointIndex i = 0; i < head.size(); ++i)
        if (brain[i] != 0) sum += head[i], sum2 += double(head[i]) * head[i], n += 1;
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    Grid<float> z(head.lattice());
    for (PointIndex i = 0; i < z.size(); ++i) z[i] = brain[i] != 0 ? static_cast<float>((head[i] - mean) / sd) : 0.0f;
    ASSERT_LT(*std::min_element(z.values().begin(), z.values().end()), -1.0f);  // CSF below the outside's 0
    BrainMaskReport r;
    BrainMaskHead found;
    const Mask mask = auto_brain_mask(z, {}, &r, &found);
    EXPECT_TRUE(r.skull_stripped);
    EXPECT_EQ(r.mid_range_fill, 0.0);
    for (PointIndex i = 0; i < mask.size(); ++i) ASSERT_EQ(mask[i], brain[i]) << i;
    ASSERT_TRUE(found.outside.dims() == z.dims());
    for (PointIndex i = 0; i < mask.size(); ++i) ASSERT_EQ(found.outside[i], 1 - brain[i]) << i;

    Grid<float> corrected = z;
    const Vec3i d = z.dims();
    for (int k = 0; k < d.z; ++k)
        for (int j = 0; j < d.y; ++j)
            for (int i = 0; i < d.x; ++i)
                corrected({i, j, k}) = brain({i, j, k}) != 0 ? 1.05f * z({i, j, k}) : 0.002f * static_cast<float>(i + j);
    BrainMaskReport again;
    const Mask same = auto_brain_mask(corrected, {}, &again, &found);
    EXPECT_EQ(again.mid_range_fill, 0.0);
    for (PointIndex i = 0; i < mask.size(); ++i) ASSERT_EQ(same[i], brain[i]) << i;

    Grid<float> stripped = head;
    for (PointIndex i = 0; i < stripped.size(); ++i)
        if (brain[i] == 0) stripped[i] = 0.0f;
    BrainMaskReport plain, full;
    BrainMaskHead plain_head;
    auto_brain_mask(stripped, {}, &plain, &plain_head);
    EXPECT_TRUE(std::isnan(plain.mid_range_fill));
    EXPECT_EQ(plain_head.outside.size(), 0u);
    auto_brain_mask(head, {}, &full);
    EXPECT_TRUE(std::isnan(full.mid_range_fill));
    // A few voxels below the outside's value are not a tissue range: a resampler's undershoot at a
    // stripped brain's edge (the mask and the default of no ROI as without it), stray negatives in
    // a head's air of zeros.
    Grid<float> undershoot = stripped, zero_air = head;
    std::size_t placed = 0;
    for (PointIndex i = 0; i < undershoot.size() && placed < 40; ++i)
        if (brain[i] != 0 && (i % 97) == 0) undershoot[i] = -2.0f, ++placed;
    for (PointIndex i = 0; i < zero_air.size(); ++i)
        if (zero_air[i] < 6.0f) zero_air[i] = (i % 5000) == 0 ? -3.0f : 0.0f;
    BrainMaskReport u, a;
    auto_brain_mask(undershoot, {}, &u);
    auto_brain_mask(zero_air, {}, &a);
    EXPECT_TRUE(std::isnan(u.mid_range_fill));
    EXPECT_TRUE(u.skull_stripped);
    EXPECT_TRUE(std::isnan(a.mid_range_fill));
}

// A brain without skull under heavy noise (the test phantom, noise 12 %, 1 x 1 x 1.5 mm): whatever
// the method finds, it is not a fragment — either it refuses with one line (callers then fit the
// model elsewhere) or the mask holds most of the grey matter.
TEST(BrainMask, ANoisyBrainWithoutSkullIsNoBrainRatherThanAFragment) {
    const liveset::testing::NoisyAnisotropicPhantom noisy = liveset::testing::noisy_anisotropic_phantom(64);
    try {
        const Mask m = auto_brain_mask(noisy.image);
        std::size_t gm = 0, gm_in = 0;
        for (PointIndex i = 0; i < m.size(); ++i) {
            gm += noisy.phantom.truth[i] != 0;
            gm_in += noisy.phantom.truth[i] != 0 && m[i] != 0;
        }
        EXPECT_GE(double(gm_in), 0.9 * double(gm));
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_TRUE(what.find("no brain") != std::string::npos || what.find("empty") != std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos);
    }
}

TEST(BrainMask, BadInputThrowsOneLine) {
    const Lattice lat({48, 48, 48});
    auto message = [](const Grid<float>& g) {
        try {
            auto_brain_mask(g);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no exception");
    };
    EXPECT_NE(message(Grid<float>(lat, 42.0f)).find("constant"), std::string::npos);
    Grid<float> noise(lat);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 100.0f);
    for (float& v : noise.values()) v = u(rng);
    EXPECT_NE(message(noise).find("no head"), std::string::npos) << message(noise);
    std::normal_distribution<float> gauss(100.0f, 20.0f);
    for (float& v : noise.values()) v = gauss(rng);
    EXPECT_NE(message(noise).find("no head"), std::string::npos) << message(noise);
    Grid<float> speck(lat, 0.0f);
    speck({20, 20, 20}) = 5.0f;
    EXPECT_NE(message(speck).find("no head"), std::string::npos) << message(speck);
    // A head with no brain: a bright 5 mm shell around a dark interior (nothing survives the erosion).
    Grid<float> shell(lat, 0.0f);
    for (int z = 0; z < 48; ++z)
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                const double r = norm(Vec3d{x - 23.5, y - 23.5, z - 23.5});
                shell({x, y, z}) = r < 15 ? 10.0f : r < 20 ? 100.0f + static_cast<float>((x * 7 + y * 3 + z) % 11) : 0.0f;
            }
    EXPECT_NE(message(shell).find("empty"), std::string::npos) << message(shell);
    Grid<float> nan = shell;
    nan({1, 2, 3}) = std::nanf("");
    EXPECT_NE(message(nan).find("NaN"), std::string::npos);
    // In the last of the check's parts (a grid of several voxel_loops::kBlock voxels, so that the
    // parts' fold runs), and NaN in the first.
    Grid<float> big(Lattice({64, 64, 64}));
    for (std::size_t i = 0; i < big.size(); ++i) big[static_cast<PointIndex>(i)] = static_cast<float>(i % 97);
    ASSERT_GE(big.size(), 3 * voxel_loops::kBlock);
    Grid<float> inf = big;
    inf({63, 63, 63}) = std::numeric_limits<float>::infinity();
    EXPECT_NE(message(inf).find("NaN or infinite"), std::string::npos) << message(inf);
    Grid<float> nan_first = big;
    nan_first({0, 0, 0}) = std::nanf("");
    EXPECT_NE(message(nan_first).find("NaN or infinite"), std::string::npos) << message(nan_first);
    BrainMaskOptions bad;
    bad.erosion_mm = -1;
    EXPECT_THROW(validate(bad), std::invalid_argument);
    bad = {};
    bad.background_fraction = 1.5;
    EXPECT_THROW(auto_brain_mask(shell, bad), std::invalid_argument);
    for (double m : {-0.5, 10.5, std::nan("")}) {
        bad = {};
        bad.noise_multiple = m;
        EXPECT_THROW(validate(bad), std::invalid_argument) << m;
    }
    for (double share : {0.0, 1.0, std::nan("")}) {
        bad = {};
        bad.noise_min_share = share;
        EXPECT_THROW(validate(bad), std::invalid_argument) << share;
    }
    for (double s : {-1.0, 11.0, std::nan("")}) {
        bad = {};
        bad.smoothing_mm = s;
        EXPECT_THROW(validate(bad), std::invalid_argument) << s;
        bad = {};
        bad.min_head_share = s / 10;
        EXPECT_THROW(validate(bad), std::invalid_argument) << s;
    }
    for (double reach : {-1.0, 51.0, std::nan("")}) {
        bad = {};
        bad.csf_reach_mm = reach;
        EXPECT_THROW(validate(bad), std::invalid_argument) << reach;
    }
}
