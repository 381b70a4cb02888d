// The coarse-to-fine start: 2x2x2 block averages, the coarse run, and its front upsampled.
#include "liveset/segment/coarse_start.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "liveset/levelset/shapes.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace {

// The fine voxels of block c along one axis: [2c, min(2c + 2, d)).
struct Span {
    int lo, hi;
};
Span block(int c, int d) { return {2 * c, std::min(2 * c + 2, d)}; }

// f(sum of value(p) over the block's fine points p as double, their count) for every coarse point,
// in parallel (each coarse point from its own block only: the same bits on any thread count).
template <class U, class V, class F>
Grid<U> reduce_blocks(const Lattice& fine, const V& value, const F& f) {
    const Lattice coarse = coarse_lattice(fine);
    Grid<U> out(coarse);
    const Vec3i cd = coarse.dims(), fd = fine.dims();
    voxel_loops::for_each(coarse.size(), [&](std::size_t i) {
        const int cx = static_cast<int>(i % static_cast<std::size_t>(cd.x));
        const int cy = static_cast<int>(i / static_cast<std::size_t>(cd.x) % static_cast<std::size_t>(cd.y));
        const int cz = static_cast<int>(i / coarse.stride_z());
        const Span x = block(cx, fd.x), y = block(cy, fd.y), z = block(cz, fd.z);
        double sum = 0.0;
        int n = 0;
        for (int k = z.lo; k < z.hi; ++k)
            for (int j = y.lo; j < y.hi; ++j)
                for (int a = x.lo; a < x.hi; ++a, ++n) sum += static_cast<double>(value(Vec3i{a, j, k}));
        out[static_cast<PointIndex>(i)] = f(sum, n);
    });
    return out;
}

// Trilinear weights along one axis for fine index i: coarse coordinate (i - 0.5) / 2, clamped.
struct Lerp {
    int a, b;
    float t;
};
Lerp lerp_at(int i, int coarse_dim) {
    const double c = std::clamp((i - 0.5) / 2.0, 0.0, static_cast<double>(coarse_dim - 1));
    const int a = std::min(static_cast<int>(std::floor(c)), coarse_dim - 1);
    return {a, std::min(a + 1, coarse_dim - 1), static_cast<float>(c - a)};
}

// The coarse φ at weights x, y, z: along x, then y, then z (one order, so every caller gets the same bits).
float trilinear(const Grid<float>& coarse_phi, const Lerp& x, const Lerp& y, const Lerp& z) {
    const auto at = [&](int a, int b, int c) { return coarse_phi(Vec3i{a, b, c}); };
    const auto along_x = [&](int b, int c) { return at(x.a, b, c) + x.t * (at(x.b, b, c) - at(x.a, b, c)); };
    const auto along_y = [&](int c) { return along_x(y.a, c) + y.t * (along_x(y.b, c) - along_x(y.a, c)); };
    return along_y(z.a) + z.t * (along_y(z.b) - along_y(z.a));
}

}  // namespace

std::string to_string(CoarseStart mode) {
    switch (mode) {
        case CoarseStart::kAuto: return "auto";
        case CoarseStart::kOn: return "on";
        case CoarseStart::kOff: return "off";
    }
    return "auto";
}

CoarseStart parse_coarse_start(const std::string& name) {
    if (name == "auto") return CoarseStart::kAuto;
    if (name == "on") return CoarseStart::kOn;
    if (name == "off") return CoarseStart::kOff;
    throw std::invalid_argument("the coarse start must be auto, on or off, got '" + name + "'");
}

bool coarse_start_applies(CoarseStart mode, const Lattice& lattice) {
    const Vec3i d = lattice.dims();
    if (mode == CoarseStart::kOff || std::min({d.x, d.y, d.z}) < kCoarseStartMinDim) return false;
    const Vec3d s = lattice.spacing();
    return mode == CoarseStart::kOn || std::max({s.x, s.y, s.z}) <= kCoarseStartMaxSpacing;
}

Lattice coarse_lattice(const Lattice& fine) {
    const Vec3i d = fine.dims();
    const Vec3d s = fine.spacing();
    return Lattice({(d.x + 1) / 2, (d.y + 1) / 2, (d.z + 1) / 2}, {2 * s.x, 2 * s.y, 2 * s.z}, fine.to_world(Vec3d{0.5, 0.5, 0.5}),
                   fine.direction());
}

Grid<std::uint8_t> downsample_majority(const Grid<std::uint8_t>& fine) {
    return reduce_blocks<std::uint8_t>(fine.lattice(), [&](Vec3i p) { return fine(p) != 0 ? 1 : 0; },
                                       [](double sum, int n) { return static_cast<std::uint8_t>(2.0 * sum >= n); });
}

Grid<float> block_threshold_terms(const ThresholdSpeed& fine) {
    const double w = 0.5 * (1.0 - fine.params().alpha);  // propagation = w·D inside the ROI, +½ (D above 1) outside
    return reduce_blocks<float>(
        fine.lattice(), [&](Vec3i q) { return std::clamp(static_cast<double>(fine.propagation(q)) / w, -1.0, 1.0); },
        [](double sum, int n) { return static_cast<float>(std::clamp(sum / n, -1.0, 1.0)); });
}

SeedBall coarse_seed(const SeedBall& fine, const Lattice& coarse) {
    const Vec3d c = fine.center;
    const Vec3i d = coarse.dims();
    const auto at = [](double x, int dim) { return std::clamp((x - 0.5) / 2.0, 0.0, dim - 1.0); };
    return {{at(c.x, d.x), at(c.y, d.y), at(c.z, d.z)}, fine.radius / 2.0};
}

float upsampled_phi(const Grid<float>& coarse_phi, Vec3i fine) {
    const Vec3i cd = coarse_phi.dims();
    return trilinear(coarse_phi, lerp_at(fine.x, cd.x), lerp_at(fine.y, cd.y), lerp_at(fine.z, cd.z));
}

Grid<std::uint8_t> upsample_inside(const Grid<float>& coarse_phi, const Lattice& fine, const Grid<std::uint8_t>* roi) {
    if (roi && !(roi->dims() == fine.dims())) throw std::invalid_argument("the ROI does not match the grid the coarse start refines");
    const Vec3i cd = coarse_phi.dims(), fd = fine.dims();
    std::vector<Lerp> lx(static_cast<std::size_t>(fd.x)), ly(static_cast<std::size_t>(fd.y)), lz(static_cast<std::size_t>(fd.z));
    for (int i = 0; i < fd.x; ++i) lx[static_cast<std::size_t>(i)] = lerp_at(i, cd.x);
    for (int i = 0; i < fd.y; ++i) ly[static_cast<std::size_t>(i)] = lerp_at(i, cd.y);
    for (int i = 0; i < fd.z; ++i) lz[static_cast<std::size_t>(i)] = lerp_at(i, cd.z);
    Grid<std::uint8_t> out(fine);
    const std::size_t rows = static_cast<std::size_t>(fd.y) * static_cast<std::size_t>(fd.z);
    voxel_loops::for_each(rows, [&](std::size_t r) {  // one fine row each
        const Lerp& y = ly[r % static_cast<std::size_t>(fd.y)];
        const Lerp& z = lz[r / static_cast<std::size_t>(fd.y)];
        for (int i = 0; i < fd.x; ++i) {
            const float v = trilinear(coarse_phi, lx[static_cast<std::size_t>(i)], y, z);
            const auto p = static_cast<PointIndex>(r * static_cast<std::size_t>(fd.x) + static_cast<std::size_t>(i));
            out[p] = v < 0.0f && (!roi || (*roi)[p] != 0);
        }
    });
    return out;
}

namespace {

// The seeds where the fine run would take them (centres inside the image, radii valid), before they
// are clamped onto the coarse grid; then mapped onto it.
std::vector<SeedBall> coarse_seeds(const Lattice& fine, const Lattice& coarse, std::span<const SeedBall> seeds) {
    std::vector<shapes::Sphere> spheres;
    for (const SeedBall& s : seeds) spheres.emplace_back(s.center, std::max(s.radius, 0.5));
    (void)shapes::SeedSpheres(fine, std::move(spheres));
    std::vector<SeedBall> balls;
    for (const SeedBall& s : seeds) balls.push_back(coarse_seed(s, coarse));
    return balls;
}

SparseField& seeded(SparseField& field, const std::vector<SeedBall>& balls) {
    init_from_seeds(field, balls);
    return field;
}

const ThresholdSpeed& same_grid(const ThresholdSpeed& fine_speed, const Lattice& fine) {
    if (!(fine_speed.lattice().dims() == fine.dims())) throw std::invalid_argument("the speed does not match the grid the coarse start refines");
    return fine_speed;
}

}  // namespace

CoarseRun::CoarseRun(const ThresholdSpeed& fine_speed, const Lattice& fine, const Grid<std::uint8_t>* roi, std::span<const SeedBall> seeds,
                     const SegmentationOptions& loop, int layers)
    : fine_(fine),
      fine_speed_(fine_speed),
      roi_(roi),
      terms_(block_threshold_terms(same_grid(fine_speed, fine))),
      coarse_roi_(roi ? std::optional(downsample_majority(*roi)) : std::nullopt),
      speed_(ThresholdSpeed::from_terms(terms_, fine_speed.params(), coarse_roi_ ? &*coarse_roi_ : nullptr)),
      field_(terms_.lattice(), layers),
      run_(seeded(field_, coarse_seeds(fine, terms_.lattice(), seeds)), speed_, loop) {}

bool CoarseRun::advance(const SegmentationHook& hook) {
    if (!hook) return run_.advance();
    return run_.advance([&](const SegmentationProgress& p, const ChangedPoints& x) {
        SegmentationProgress q = p;
        q.level = 1;
        return hook(q, x);
    });
}

std::optional<Grid<std::uint8_t>> CoarseRun::fine_start(CoarseStartReport& report) const {
    report.dims = field_.lattice().dims();
    report.spacing = field_.lattice().spacing();
    report.result = run_.result();
    if (!run_.ended() || report.result.reason == StopReason::kInterrupted) return std::nullopt;
    Grid<std::uint8_t> start = upsample_inside(field_.phi(), fine_, roi_);
    const auto inside = [&] { return voxel_loops::count_if(start.size(), [&](std::size_t i) { return start[static_cast<PointIndex>(i)] != 0; }); };
    const std::size_t upsampled = inside();
    voxel_loops::for_each(start.size(), [&](std::size_t i) {  // the image's own data term refuses it: left out
        const auto p = static_cast<PointIndex>(i);
        if (start[p] != 0 && fine_speed_.propagation(fine_.coord(p)) > 0.0f) start[p] = 0;
    });
    report.upsampled = inside();
    report.refused = upsampled - report.upsampled;
    report.used = report.upsampled > 0;
    if (!report.used) return std::nullopt;
    return start;
}

void init_fine_start(SparseField& fine, const std::optional<Grid<std::uint8_t>>& start, std::span<const SeedBall> seeds) {
    if (!start) {
        init_from_seeds(fine, seeds);
        return;
    }
    fine.init_from_mask(*start);
    unite_seeds(fine, seeds);
}

std::optional<Grid<std::uint8_t>> run_coarse_start(const ThresholdSpeed& fine_speed, const Lattice& fine,
                                                   const Grid<std::uint8_t>* roi, std::span<const SeedBall> seeds,
                                                   const SegmentationOptions& loop, int layers, const SegmentationHook& hook,
                                                   const std::atomic<bool>* interrupt, CoarseStartReport& report) {
    CoarseRun run(fine_speed, fine, roi, seeds, loop, layers);
    const auto start = std::chrono::steady_clock::now();
    for (;;) {
        if (interrupt && interrupt->load(std::memory_order_relaxed)) run.interrupt();
        if (!run.advance(hook)) break;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();  // the loop's, as before
    std::optional<Grid<std::uint8_t>> fine_start = run.fine_start(report);
    report.result.seconds = seconds;
    return fine_start;
}

}  // namespace liveset
