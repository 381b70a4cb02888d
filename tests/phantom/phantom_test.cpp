// Phantom tests: determinism (seeds, thread counts), nested anatomy and GM truth, intensities,
// noise level, bias field, the key property (the global GM window perforates the thresholded shell
// at the weak spots and nowhere in the opposite half), seeds, weak spots and option validation.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "liveset/eval/topology.hpp"
#include "liveset/phantom/phantom.hpp"

using namespace liveset;

namespace {

const Vec3i kFaces[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

PhantomOptions sized(int size) {
    PhantomOptions o;
    o.size = size;
    return o;
}

// The default phantoms, built once.
const Phantom& phantom96() {
    static const Phantom p = make_phantom(sized(96));
    return p;
}
const Phantom& phantom64() {
    static const Phantom p = make_phantom(sized(64));
    return p;
}

template <class T>
bool same_bytes(const Grid<T>& a, const Grid<T>& b) {
    return a.size() == b.size() && std::memcmp(a.values().data(), b.values().data(), a.size() * sizeof(T)) == 0;
}

bool on_border(const Lattice& l, Vec3i c) {
    const Vec3i d = l.dims();
    return c.x == 0 || c.y == 0 || c.z == 0 || c.x == d.x - 1 || c.y == d.y - 1 || c.z == d.z - 1;
}

// 6-connected flood from the border voxels with pass(c) through voxels with pass(c).
template <class Pass>
std::vector<char> flood_from_border(const Lattice& l, Pass pass) {
    std::vector<char> seen(l.size(), 0);
    std::deque<PointIndex> queue;
    for (PointIndex i = 0; i < l.size(); ++i) {
        const Vec3i c = l.coord(i);
        if (on_border(l, c) && pass(c)) {
            seen[i] = 1;
            queue.push_back(i);
        }
    }
    while (!queue.empty()) {
        const Vec3i c = l.coord(queue.front());
        queue.pop_front();
        for (const Vec3i& e : kFaces) {
            const Vec3i q = c + e;
            if (!l.contains(q)) continue;
            const PointIndex j = l.index(q);
            if (seen[j] || !pass(q)) continue;
            seen[j] = 1;
            queue.push_back(j);
        }
    }
    return seen;
}

std::size_t count_label_reached(const Phantom& p, const std::vector<char>& seen, std::uint8_t label) {
    std::size_t n = 0;
    for (PointIndex i = 0; i < p.labels.size(); ++i) n += seen[i] && p.labels[i] == label;
    return n;
}

bool is_out_of_window(const Phantom& p, const IntensityWindow& w, Vec3i c) { return !w.contains(p.image(c)); }

int squared_distance(Vec3i a, Vec3i b) {
    const Vec3i d = a - b;
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

}  // namespace

// --- determinism -------------------------------------------------------------------------------

TEST(Phantom, SameOptionsGiveIdenticalBytes) {
    const Phantom a = make_phantom(sized(64));
    const Phantom& b = phantom64();
    EXPECT_TRUE(same_bytes(a.image, b.image));
    EXPECT_TRUE(same_bytes(a.labels, b.labels));
    EXPECT_TRUE(same_bytes(a.truth, b.truth));
    EXPECT_TRUE(same_bytes(a.bias_field, b.bias_field));
    EXPECT_EQ(a.seeds, b.seeds);
    EXPECT_EQ(a.weak_spots, b.weak_spots);
}

TEST(Phantom, NoiseSeedChangesOnlyTheNoise) {
    PhantomOptions o = sized(64);
    o.seed = 2;
    const Phantom a = make_phantom(o);
    const Phantom& b = phantom64();
    EXPECT_TRUE(same_bytes(a.labels, b.labels));
    EXPECT_TRUE(same_bytes(a.bias_field, b.bias_field));
    std::size_t differ = 0;
    for (PointIndex i = 0; i < a.image.size(); ++i) differ += a.image[i] != b.image[i];
    EXPECT_GT(differ, a.image.size() * 9 / 10);  // fresh noise nearly everywhere
}

TEST(Phantom, AnatomySeedChangesTheFolds) {
    PhantomOptions o = sized(64);
    o.anatomy_seed = 7;
    const Phantom a = make_phantom(o);
    EXPECT_FALSE(same_bytes(a.labels, phantom64().labels));
}

TEST(Phantom, IdenticalForOneAndTwoThreads) {
    PhantomOptions o = sized(64);
    o.seed = 5;
    Phantom one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = make_phantom(o);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = make_phantom(o);
    }
    EXPECT_TRUE(same_bytes(one.image, two.image));
    EXPECT_TRUE(same_bytes(one.labels, two.labels));
    EXPECT_TRUE(same_bytes(one.bias_field, two.bias_field));
    EXPECT_EQ(one.seeds, two.seeds);
    EXPECT_EQ(one.weak_spots, two.weak_spots);
}

// --- geometry and anatomy ----------------------------------------------------------------------

TEST(Phantom, LatticeIsCentredOnTheOrigin) {
    PhantomOptions o = sized(64);
    o.spacing_mm = 1.5;
    const Phantom p = make_phantom(o);
    const Lattice& l = p.image.lattice();
    EXPECT_EQ(l.dims(), (Vec3i{64, 64, 64}));
    EXPECT_EQ(l.spacing(), (Vec3d{1.5, 1.5, 1.5}));
    const Vec3d centre = l.to_world({31.5, 31.5, 31.5});
    EXPECT_NEAR(centre.x, 0.0, 1e-9);
    EXPECT_NEAR(centre.y, 0.0, 1e-9);
    EXPECT_NEAR(centre.z, 0.0, 1e-9);
    for (const auto* lat : {&p.labels.lattice(), &p.truth.lattice(), &p.bias_field.lattice()})
        EXPECT_TRUE(lat->same_geometry(l));
}

TEST(Phantom, TruthIsTheGreyMatterLabel) {
    const Phantom& p = phantom96();
    std::size_t counts[4] = {0, 0, 0, 0};
    for (PointIndex i = 0; i < p.labels.size(); ++i) {
        ASSERT_LE(p.labels[i], 3);
        ++counts[p.labels[i]];
        ASSERT_EQ(p.truth[i], p.labels[i] == kGreyMatter ? 1 : 0);
    }
    for (std::size_t c : counts) EXPECT_GT(c, 1000u);
}

// WM enclosed by GM (at least 2 voxels along every axis), GM enclosed by CSF.
void expect_nested(const Phantom& p) {
    const Lattice& l = p.labels.lattice();
    std::size_t wm_touching_outside = 0, thin_gm = 0, gm_touching_background = 0;
    for (PointIndex i = 0; i < l.size(); ++i) {
        const Vec3i c = l.coord(i);
        if (p.labels[i] == kWhiteMatter) {
            for (const Vec3i& e : kFaces)
                for (int k = 1; k <= 2; ++k) {
                    const Vec3i q = c + e * k;
                    ASSERT_TRUE(l.contains(q));
                    if (p.labels(q) == kCsf || p.labels(q) == kBackground) (k == 1 ? wm_touching_outside : thin_gm)++;
                }
        } else if (p.labels[i] == kGreyMatter) {
            for (const Vec3i& e : kFaces) gm_touching_background += p.labels(c + e) == kBackground;
        }
    }
    EXPECT_EQ(wm_touching_outside, 0u);
    EXPECT_EQ(thin_gm, 0u);
    EXPECT_EQ(gm_touching_background, 0u);
}

TEST(Phantom, TissuesAreNested) {
    expect_nested(phantom96());
    expect_nested(phantom64());
    PhantomOptions o = sized(48);
    o.spacing_mm = 2.0;  // thickness clamped to 2.5 voxels
    o.anatomy_seed = 3;
    expect_nested(make_phantom(o));
}

TEST(Phantom, GreyMatterShellIsOneComponentEnclosingTheWhiteMatter) {
    for (const Phantom* p : {&phantom96(), &phantom64()}) {
        const Lattice& l = p->labels.lattice();
        // One 26-connected GM component.
        std::vector<char> seen(l.size(), 0);
        std::size_t components = 0;
        for (PointIndex s = 0; s < l.size(); ++s) {
            if (p->labels[s] != kGreyMatter || seen[s]) continue;
            ++components;
            std::deque<PointIndex> queue{s};
            seen[s] = 1;
            while (!queue.empty()) {
                const Vec3i c = l.coord(queue.front());
                queue.pop_front();
                for (int dz = -1; dz <= 1; ++dz)
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const Vec3i q = c + Vec3i{dx, dy, dz};
                            if (!l.contains(q)) continue;
                            const PointIndex j = l.index(q);
                            if (p->labels[j] == kGreyMatter && !seen[j]) {
                                seen[j] = 1;
                                queue.push_back(j);
                            }
                        }
            }
        }
        EXPECT_EQ(components, 1u);
        // The outside cannot reach the WM without crossing GM.
        const auto outside = flood_from_border(l, [&](Vec3i c) { return p->labels(c) != kGreyMatter; });
        EXPECT_EQ(count_label_reached(*p, outside, kWhiteMatter), 0u);
        EXPECT_GT(count_label_reached(*p, outside, kCsf), 0u);
    }
}

// The truth is one closed shell (euler 4, no tunnel, the WM its only cavity) whatever the size and
// folds, so `holes` measures a segmentation and not the anatomy. (Before the radial closure and
// the topology-preserving regrowth, the 128^3 default had 77 cavities and genus 68.)
TEST(Phantom, GreyMatterTruthIsATopologicallyCleanShell) {
    std::vector<PhantomOptions> cases;
    for (int size : {64, 96, 128}) cases.push_back(sized(size));
    PhantomOptions deep = sized(96);
    deep.fold_depth = 1.5;
    deep.anatomy_seed = 3;
    cases.push_back(deep);
    for (const PhantomOptions& o : cases) {
        const Phantom p = make_phantom(o);
        const Topology t = mask_topology(p.truth);
        EXPECT_EQ(t.components, 1u) << o.size;
        EXPECT_EQ(t.cavities, 1u) << o.size;
        EXPECT_EQ(t.genus, 0) << o.size;
        EXPECT_EQ(t.euler, 4) << o.size;
    }
}

TEST(Phantom, WhiteMatterSurfaceIsFolded) {
    // The WM surface is folded: its radius along rays from the centre varies by several voxels.
    const Phantom& p = phantom96();
    const Lattice& l = p.labels.lattice();
    double min_r = 1e9, max_r = 0;
    for (int a = 0; a < 64; ++a) {
        const double t = 2.0 * 3.14159265358979 * a / 64;
        const Vec3d dir{std::cos(t), std::sin(t), 0.0};
        double last_wm = 0;
        for (double r = 0; r < 48; r += 0.25) {
            const Vec3i q = (Vec3d{47.5, 47.5, 47.5} + dir * r + Vec3d{0.5, 0.5, 0.5}).cast<int>();
            if (!l.contains(q)) break;
            if (p.labels(q) == kWhiteMatter) last_wm = r;
        }
        min_r = std::min(min_r, last_wm);
        max_r = std::max(max_r, last_wm);
    }
    EXPECT_GT(max_r - min_r, 5.0);
}

// --- intensities, noise, bias ------------------------------------------------------------------

TEST(Phantom, MeanIntensitiesAreOrderedLikeT1) {
    PhantomOptions clean = sized(64);
    clean.noise = 0;
    clean.bias = 0;
    for (const PhantomOptions& o : {clean, sized(64)}) {
        const Phantom p = make_phantom(o);
        double sum[4] = {0, 0, 0, 0};
        std::size_t n[4] = {0, 0, 0, 0};
        for (PointIndex i = 0; i < p.labels.size(); ++i) {
            sum[p.labels[i]] += p.image[i];
            ++n[p.labels[i]];
        }
        const double bg = sum[0] / n[0], csf = sum[1] / n[1], gm = sum[2] / n[2], wm = sum[3] / n[3];
        EXPECT_GT(wm, gm);
        EXPECT_GT(gm, csf);
        EXPECT_GT(csf, bg);
        EXPECT_GT(p.wm_intensity, p.gm_intensity);
        EXPECT_GT(p.gm_intensity, p.csf_intensity);
        EXPECT_GT(p.csf_intensity, p.background_intensity);
        if (o.noise == 0) {  // partial volume only moves the class means a little
            EXPECT_NEAR(wm, p.wm_intensity, 0.05 * p.wm_intensity);
            EXPECT_NEAR(gm, p.gm_intensity, 0.08 * p.gm_intensity);
            EXPECT_NEAR(csf, p.csf_intensity, 0.15 * p.csf_intensity);
            EXPECT_NEAR(bg, p.background_intensity, 0.01 * p.wm_intensity);
        }
    }
}

TEST(Phantom, NoiseSigmaMatchesTheOption) {
    // Deep WM (no partial volume): the noisy image minus the noise-free one is the noise.
    PhantomOptions o = sized(64);
    o.noise = 0.05;
    PhantomOptions quiet = o;
    quiet.noise = 0;
    const Phantom clean = make_phantom(quiet);
    for (const bool rician : {false, true}) {
        o.rician = rician;
        const Phantom noisy = make_phantom(o);
        const Lattice& l = clean.labels.lattice();
        double sum = 0, sum2 = 0;
        std::size_t n = 0;
        for (PointIndex i = 0; i < l.size(); ++i) {
            const Vec3i c = l.coord(i);
            if (on_border(l, c)) continue;
            bool deep = true;
            for (int dz = -1; dz <= 1 && deep; ++dz)
                for (int dy = -1; dy <= 1 && deep; ++dy)
                    for (int dx = -1; dx <= 1 && deep; ++dx) deep = clean.labels(c + Vec3i{dx, dy, dz}) == kWhiteMatter;
            if (!deep) continue;
            const double r = static_cast<double>(noisy.image[i]) - clean.image[i];
            sum += r;
            sum2 += r * r;
            ++n;
        }
        ASSERT_GT(n, 2000u);
        const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
        const double expected = o.noise * noisy.wm_intensity;
        EXPECT_NEAR(sigma, expected, 0.05 * expected) << "rician " << rician;
        EXPECT_NEAR(mean, 0.0, 0.1 * expected) << "rician " << rician;
    }
}

TEST(Phantom, BackgroundIsDarkAndRicianNoiseNonNegative) {
    const Phantom& p = phantom64();
    double sum = 0;
    std::size_t n = 0;
    for (PointIndex i = 0; i < p.image.size(); ++i) {
        ASSERT_GE(p.image[i], 0.0f);
        if (p.labels[i] == kBackground) {
            sum += p.image[i];
            ++n;
        }
    }
    EXPECT_LT(sum / n, 0.1 * p.wm_intensity);  // Rayleigh floor of the noise only
}

TEST(Phantom, BiasFieldIsSmoothBoundedAndApplied) {
    const PhantomOptions o = sized(96);
    const Phantom& p = phantom96();
    const Lattice& l = p.bias_field.lattice();
    const int n = o.size;
    float lo = 10, hi = 0, lower_half_max = 0, max_step = 0, max_curve = 0;
    for (PointIndex i = 0; i < l.size(); ++i) {
        const Vec3i c = l.coord(i);
        const float b = p.bias_field[i];
        lo = std::min(lo, b);
        hi = std::max(hi, b);
        if (c.z < n / 2) lower_half_max = std::max(lower_half_max, b);
        for (int a = 0; a < 3; ++a) {
            Vec3i e{0, 0, 0};
            e[a] = 1;
            if (!l.contains(c + e) || !l.contains(c - e)) continue;
            max_step = std::max(max_step, std::abs(p.bias_field(c + e) - b));
            max_curve = std::max(max_curve, std::abs(p.bias_field(c + e) - 2 * b + p.bias_field(c - e)));
        }
    }
    EXPECT_GE(lo, 1.0f);
    EXPECT_LE(hi, 1.0f + static_cast<float>(o.bias) + 1e-5f);
    EXPECT_GT(hi, 1.0f + 0.9f * static_cast<float>(o.bias));  // strong somewhere
    EXPECT_LT(lower_half_max, 1.0f + 0.15f * static_cast<float>(o.bias));  // weak opposite
    // Smooth: first and second differences per voxel bounded relative to the bias amplitude
    // (Gaussian bumps with sigma >= 0.1 L).
    EXPECT_LT(max_step, 0.13f * static_cast<float>(o.bias));
    EXPECT_LT(max_curve, 0.045f * static_cast<float>(o.bias));

    // The image is the bias field times the unbiased image (noise off).
    PhantomOptions flat = sized(64), biased = sized(64);
    flat.noise = biased.noise = 0;
    flat.bias = 0;
    const Phantom a = make_phantom(flat), b = make_phantom(biased);
    for (PointIndex i = 0; i < a.bias_field.size(); ++i) {
        ASSERT_EQ(a.bias_field[i], 1.0f);
        ASSERT_NEAR(b.image[i], b.bias_field[i] * a.image[i], 1e-3f * b.image[i] + 1e-3f);
    }
}

// --- the key property: perforations at the weak spots, intact elsewhere -------------------------

void expect_perforated_at_weak_spots_only(const Phantom& p) {
    const Lattice& l = p.image.lattice();
    const int n = l.dims().z;
    const IntensityWindow w = gm_window(p);
    EXPECT_FLOAT_EQ(w.lo, p.gm_intensity - 0.5f * (p.gm_intensity - p.csf_intensity));
    EXPECT_FLOAT_EQ(w.hi, p.gm_intensity + 0.5f * (p.wm_intensity - p.gm_intensity));
    ASSERT_EQ(p.weak_spots.size(), 2u);
    // Near each weak spot, a 6-path of out-of-window voxels joins the outside to the WM, crossing
    // the GM truth only within 6 voxels of the weak spot.
    for (const Vec3i& spot : p.weak_spots) {
        const auto seen = flood_from_border(l, [&](Vec3i c) {
            return is_out_of_window(p, w, c) && (p.labels(c) != kGreyMatter || squared_distance(c, spot) <= 36);
        });
        EXPECT_GT(count_label_reached(p, seen, kWhiteMatter), 0u) << "no perforation at " << spot;
    }
    // In the inferior half (opposite the bias peaks) the thresholded shell separates the WM from
    // the outside: no such path stays below the mid plane.
    const auto lower = flood_from_border(l, [&](Vec3i c) { return c.z < n / 2 && is_out_of_window(p, w, c); });
    EXPECT_EQ(count_label_reached(p, lower, kWhiteMatter), 0u);
}

TEST(Phantom, GlobalWindowPerforatesTheShellAtTheWeakSpotsOnly) {
    expect_perforated_at_weak_spots_only(phantom96());
    expect_perforated_at_weak_spots_only(phantom64());
    PhantomOptions o = sized(64);
    o.seed = 11;
    expect_perforated_at_weak_spots_only(make_phantom(o));
}

TEST(Phantom, WithoutBiasTheThresholdedShellIsIntact) {
    PhantomOptions o = sized(64);
    o.bias = 0;
    const Phantom p = make_phantom(o);
    const IntensityWindow w = gm_window(p);
    const auto seen = flood_from_border(p.image.lattice(), [&](Vec3i c) { return is_out_of_window(p, w, c); });
    EXPECT_EQ(count_label_reached(p, seen, kWhiteMatter), 0u);
}

// --- seeds and weak spots ----------------------------------------------------------------------

TEST(Phantom, SeedsLieDeepInGreyMatterInsideTheWindowAwayFromTheBias) {
    for (const Phantom* p : {&phantom96(), &phantom64()}) {
        const IntensityWindow w = gm_window(*p);
        ASSERT_GE(p->seeds.size(), 3u);
        ASSERT_LE(p->seeds.size(), 6u);
        for (const Vec3i& s : p->seeds) {
            ASSERT_TRUE(p->labels.lattice().contains(s));
            EXPECT_EQ(p->labels(s), kGreyMatter);
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) EXPECT_EQ(p->labels(s + Vec3i{dx, dy, dz}), kGreyMatter) << s;
            EXPECT_TRUE(w.contains(p->image(s))) << s;
            EXPECT_LT(p->bias_field(s), 1.0f + 0.3f * static_cast<float>(sized(64).bias));
            const int far = p->labels.lattice().dims().x / 6;
            for (const Vec3i& spot : p->weak_spots) EXPECT_GT(squared_distance(s, spot), far * far);
        }
    }
}

TEST(Phantom, WeakSpotsAreGreyMatterWhereTheBiasPeaks) {
    const Phantom& p = phantom96();
    float gm_max = 0;
    for (PointIndex i = 0; i < p.labels.size(); ++i)
        if (p.labels[i] == kGreyMatter) gm_max = std::max(gm_max, p.bias_field[i]);
    for (const Vec3i& spot : p.weak_spots) {
        EXPECT_EQ(p.labels(spot), kGreyMatter);
        EXPECT_GT(p.bias_field(spot), 1.0f + 0.85f * static_cast<float>(sized(96).bias));
        // Its noise-free intensity is out of the window (above it).
        EXPECT_GT(p.gm_intensity * p.bias_field(spot), gm_window(p).hi);
    }
    EXPECT_GE(p.bias_field(p.weak_spots[0]), gm_max - 0.02f);
}

// --- options -----------------------------------------------------------------------------------

TEST(Phantom, DefaultsAreValid) {
    const PhantomOptions o;
    EXPECT_EQ(o.size, 128);
    EXPECT_NO_THROW(validate(o));
    EXPECT_NO_THROW(validate(sized(32)));
    EXPECT_NO_THROW(validate(sized(512)));
}

TEST(Phantom, BadOptionsThrowWithOneLineMessages) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<PhantomOptions> bad;
    auto with = [&](auto edit) {
        PhantomOptions o;
        edit(o);
        bad.push_back(o);
    };
    with([](PhantomOptions& o) { o.size = 31; });
    with([](PhantomOptions& o) { o.size = 513; });
    with([](PhantomOptions& o) { o.size = -5; });
    with([](PhantomOptions& o) { o.spacing_mm = 0; });
    with([](PhantomOptions& o) { o.spacing_mm = -1; });
    with([&](PhantomOptions& o) { o.spacing_mm = nan; });
    with([&](PhantomOptions& o) { o.spacing_mm = inf; });
    with([](PhantomOptions& o) { o.noise = -0.01; });
    with([&](PhantomOptions& o) { o.noise = nan; });
    with([](PhantomOptions& o) { o.noise = 0.9; });
    with([](PhantomOptions& o) { o.bias = -0.1; });
    with([](PhantomOptions& o) { o.bias = 1.5; });
    with([&](PhantomOptions& o) { o.bias = inf; });
    with([](PhantomOptions& o) { o.fold_depth = -1; });
    with([](PhantomOptions& o) { o.fold_depth = 3; });
    with([](PhantomOptions& o) { o.gm_thickness_min_mm = 0; });
    with([&](PhantomOptions& o) { o.gm_thickness_min_mm = nan; });
    with([](PhantomOptions& o) { o.gm_thickness_max_mm = 2.0; });  // below the minimum
    with([](PhantomOptions& o) { o.gm_thickness_max_mm = 11.0; });
    with([](PhantomOptions& o) { o.csf_thickness_mm = -1; });
    with([&](PhantomOptions& o) { o.csf_thickness_mm = nan; });
    with([](PhantomOptions& o) { o.blur = -0.5; });
    with([](PhantomOptions& o) { o.blur = 5; });
    with([](PhantomOptions& o) {  // too small a field of view for the layers
        o.size = 32;
        o.gm_thickness_min_mm = 8;
        o.gm_thickness_max_mm = 9;
    });
    for (std::size_t k = 0; k < bad.size(); ++k) {
        try {
            validate(bad[k]);
            ADD_FAILURE() << "case " << k << " did not throw";
        } catch (const std::invalid_argument& e) {
            const std::string msg = e.what();
            EXPECT_FALSE(msg.empty());
            EXPECT_EQ(msg.find('\n'), std::string::npos);
            EXPECT_EQ(msg.rfind("phantom: ", 0), 0u) << msg;
        }
        EXPECT_THROW(make_phantom(bad[k]), std::invalid_argument) << "case " << k;
    }
}

TEST(Phantom, OptionsShapeTheAnatomy) {
    // Without folds (a smooth ellipsoidal WM core) the tissues are still nested.
    PhantomOptions o = sized(64);
    o.fold_depth = 0;
    o.noise = 0;
    const Phantom smooth = make_phantom(o);
    expect_nested(smooth);
    // Thicker GM gives more GM voxels.
    PhantomOptions thick = sized(64);
    thick.gm_thickness_min_mm = 3.5;
    thick.gm_thickness_max_mm = 5.0;
    std::size_t gm_default = 0, gm_thick = 0;
    const Phantom t = make_phantom(thick);
    for (PointIndex i = 0; i < t.labels.size(); ++i) {
        gm_default += phantom64().labels[i] == kGreyMatter;
        gm_thick += t.labels[i] == kGreyMatter;
    }
    EXPECT_GT(gm_thick, gm_default * 11 / 10);
    expect_nested(t);
}
