// Bias-field correction: ITK's N4 on a subsampled copy of the image, its B-spline log field
// evaluated on the full-resolution grid and divided out; Otsu's foreground as the default fit mask.
#include "liveset/preprocess/bias_correction.hpp"

#include "liveset/grid/reorient.hpp"
#include "liveset/preprocess/bspline_field.hpp"
#include "liveset/segment/tissue_model.hpp"
#include "liveset/base/stopwatch.hpp"

#include <itkImage.h>
#include <itkIterationReporter.h>
#include <itkMultiThreaderBase.h>
#include <itkObjectFactoryBase.h>
#include <itkVersion.h>
#include <itkN4BiasFieldCorrectionImageFilter.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

namespace liveset {

namespace {

using FloatImage = itk::Image<float, 3>;
using MaskImage = itk::Image<unsigned char, 3>;
using N4Filter = itk::N4BiasFieldCorrectionImageFilter<FloatImage, MaskImage, FloatImage>;
using ControlLattice = N4Filter::BiasFieldControlPointLatticeType;
using Clock = std::chrono::steady_clock;

[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument("bias correction: " + what); }

std::string dims_text(Vec3i d) {
    std::ostringstream os;
    os << d.x << 'x' << d.y << 'x' << d.z;
    return os.str();
}

void check_option(double value, double low, double high, const char* what) {
    if (std::isfinite(value) && value >= low && value <= high) return;
    std::ostringstream os;
    os << what << " must be in [" << low << ", " << high << "] (got " << value << ")";
    fail(os.str());
}

// Inputs N4 can work with: a non-empty image with >= 2 voxels per axis, finite values, and a mask
// (when given) on the same lattice.
void check_inputs(const Grid<float>& image, const Grid<std::uint8_t>* mask) {
    const Vec3i d = image.dims();
    if (image.size() == 0) fail("the image is empty");
    if (d.x < 2 || d.y < 2 || d.z < 2) fail("the image is " + dims_text(d) + "; it needs at least 2 voxels along each axis");
    std::size_t bad = 0;
    for (float v : image.values()) bad += !std::isfinite(v);
    if (bad > 0) fail(std::to_string(bad) + " voxels are NaN or infinite");
    if (mask == nullptr) return;
    if (mask->dims() != d) fail("the mask is " + dims_text(mask->dims()) + ", the image " + dims_text(d));
    if (!mask->lattice().same_geometry(image.lattice())) fail("the mask does not overlay the image (spacing, origin or direction differ)");
}

// The voxels that drive the fit: the mask's (or Otsu's foreground) with an intensity > 0.
Grid<std::uint8_t> fit_mask(const Grid<float>& image, const Grid<std::uint8_t>* mask, BiasCorrectionReport& report) {
    Grid<std::uint8_t> fit = mask != nullptr ? *mask : otsu_foreground(image);
    report.otsu_mask = mask == nullptr;
    std::size_t count = 0;
    for (std::size_t i = 0; i < fit.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        fit[p] = fit[p] != 0 && image[p] > 0.0f;
        count += fit[p];
    }
    if (count == 0) fail(mask != nullptr ? "the mask holds no voxel with an intensity > 0" : "the image holds no voxel > 0");
    report.mask_voxels = count;
    return fit;
}

// The voxel size's last bits must not reach N4: the same data as NIfTI (spacing in float:
// 1.2000000477 mm) and as MINC (in double: 1.1999999552 mm once its direction cosines are
// normalised) must get the same field, and N4's fit turned that 6e-8 into fields 0.3 % apart (a
// phantom and its nii2mnc copy: masks a few voxels apart). So N4 works in index units (its
// B-spline's parametric coordinates are then ratios of sample indices, exact), and millimetres only
// pick whole numbers - the shrink factors and the control points - with this margin, so that a
// ratio within it of a rounding boundary (6 mm / 1.3333 mm = 4.5) goes the same way for both.
constexpr double kMmMargin = 1e-6;
// Unit spacing: what N4 and the field's evaluation are told.
constexpr Vec3d kIndexUnits{1.0, 1.0, 1.0};

// The shrunk grid: along each axis samples 0, f, 2f, ... up to the first one at or past the last
// voxel (n_s = ceil((n-1)/f) + 1), so its span (n_s-1)·f covers the image's n-1 exactly or with a
// few padding samples (value 0, outside the fit mask). Its voxel i is full-resolution voxel i·f,
// so the B-spline domain of the fit maps onto the full grid without any resampling.
struct ShrinkPlan {
    Vec3i factors{1, 1, 1};
    Vec3i dims{0, 0, 0};
    Vec3i span{0, 0, 0};  // full-resolution voxels covered: (n_s - 1)·f + 1 >= n
};

ShrinkPlan plan_shrink(Vec3i dims, Vec3d spacing, double shrink_mm) {
    ShrinkPlan plan;
    for (int a = 0; a < 3; ++a) {
        const int n = dims[a];
        const int f = std::clamp(static_cast<int>(std::floor(shrink_mm / spacing[a] + 0.5 - kMmMargin)), 1, n - 1);
        plan.factors[a] = f;
        plan.dims[a] = (n - 1 + f - 1) / f + 1;
        plan.span[a] = (plan.dims[a] - 1) * f + 1;
    }
    return plan;
}

// The shrunk grid filled with value(p) at each sample's full-resolution voxel p = j·f (the
// padding samples past the image's end stay 0).
template <class Image, class Value>
typename Image::Pointer shrunk_image(const Vec3i& n, const ShrinkPlan& plan, const Value& value) {
    auto out = Image::New();
    typename Image::SizeType size;
    for (int a = 0; a < 3; ++a) size[a] = static_cast<itk::SizeValueType>(plan.dims[a]);
    out->SetRegions(size);  // unit spacing, origin 0, identity direction: index units (kMmMargin)
    out->Allocate(true);
    auto* dst = out->GetBufferPointer();
    std::size_t k = 0;
    for (int z = 0; z < plan.dims.z; ++z)
        for (int y = 0; y < plan.dims.y; ++y)
            for (int x = 0; x < plan.dims.x; ++x, ++k) {
                const Vec3i p{x * plan.factors.x, y * plan.factors.y, z * plan.factors.z};
                if (p.x < n.x && p.y < n.y && p.z < n.z) dst[k] = value(p);
            }
    return out;
}

// The median of the fit voxels in the 3×3×3 neighbourhood of a fit voxel c
// (BiasCorrectionOptions::denoise). N4 sharpens the histogram of its samples, and a plain subsample
// keeps all of the scan's noise in it: on BrainWeb + noise σ 9 (no bias at all) N4 fitted a field of
// 0.63..1.32 and the tissue model merged GM with WM. The median divides Gaussian noise by about 4
// and keeps tissue edges (a block mean blurred them: Dice −0.02 on the clean scan).
float fit_median(const Grid<float>& full, const Grid<std::uint8_t>& fit, Vec3i c) {
    std::array<float, 27> v{};
    int count = 0;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const Vec3i q = c + Vec3i{dx, dy, dz};
                if (full.lattice().contains(q) && fit(q) != 0) v[static_cast<std::size_t>(count++)] = full(q);
            }
    std::nth_element(v.begin(), v.begin() + count / 2, v.begin() + count);
    return v[static_cast<std::size_t>(count / 2)];
}

// ITK's work split onto TBB (use_tbb_work_units below): every work unit of a filter runs as a TBB
// task, so ITK honours --threads (TBB's allowed parallelism) as liveset's own loops do, and a
// filter gets a fixed number of work units whatever the machine. ITK's own pool threader cannot
// do either: it runs each work unit on a pool thread (as many as the machine's cores), and a
// filter's default count of work units follows its thread count (1 thread: 1, 2: 8).
class TbbWorkUnits : public itk::MultiThreaderBase {
public:
    using Self = TbbWorkUnits;
    using Superclass = itk::MultiThreaderBase;
    using Pointer = itk::SmartPointer<Self>;
    itkNewMacro(Self);
    itkTypeMacro(TbbWorkUnits, itk::MultiThreaderBase);

    // The work units every filter gets. ITK's scattered-data B-spline fit (N4's costly part) sums
    // one partial control lattice per work unit, in unit order: a fixed count gives the same sums,
    // and so the same bits, on any number of threads. Eight keep two to eight cores busy.
    static constexpr itk::ThreadIdType kWorkUnits = 8;

    void SetSingleMethod(itk::ThreadFunctionType f, void* data) override {
        method_ = f;
        data_ = data;
    }
    void SingleMethodExecute() override {
        const itk::ThreadIdType n = this->GetNumberOfWorkUnits();
        std::vector<WorkUnitInfo> units(n);
        tbb::this_task_arena::isolate([&] {  // a caller inside a TBB task waits for these units only
            tbb::parallel_for(itk::ThreadIdType{0}, n, [&](itk::ThreadIdType i) {
                units[i].WorkUnitID = i;
                units[i].NumberOfWorkUnits = n;
                units[i].UserData = data_;
                units[i].ThreadFunction = method_;
                units[i].ThreadExitCode = WorkUnitInfo::ThreadExitCodeEnum::SUCCESS;
                method_(&units[i]);
            });
        });
    }

protected:
    TbbWorkUnits() {
        Superclass::SetMaximumNumberOfThreads(kWorkUnits);
        Superclass::SetNumberOfWorkUnits(kWorkUnits);
    }

private:
    itk::ThreadFunctionType method_ = nullptr;
    void* data_ = nullptr;
};

class TbbWorkUnitsFactory : public itk::ObjectFactoryBase {
public:
    using Self = TbbWorkUnitsFactory;
    using Pointer = itk::SmartPointer<Self>;
    itkFactorylessNewMacro(Self);
    itkTypeMacro(TbbWorkUnitsFactory, itk::ObjectFactoryBase);
    const char* GetITKSourceVersion() const override { return ITK_SOURCE_VERSION; }
    const char* GetDescription() const override { return "liveset: ITK work units as TBB tasks"; }

protected:
    TbbWorkUnitsFactory() {
        // ObjectFactory<T>::Create looks overrides up by typeid(T).name().
        this->RegisterOverride(typeid(itk::MultiThreaderBase).name(), "TbbWorkUnits", "ITK work units as TBB tasks", true,
                               itk::CreateObjectFunction<TbbWorkUnits>::New());
    }
};

// From the first bias correction on, every ITK filter the process creates gets the TbbWorkUnits
// threader (N4 creates its filters inside). Registered once and never removed: ITK's factory list
// has no lock, and other threads (Python's, Dask's) may create ITK objects at any time.
void use_tbb_work_units() {
    static std::once_flag once;
    std::call_once(once, [] { itk::ObjectFactoryBase::RegisterFactory(TbbWorkUnitsFactory::New()); });
}

// True when the fit voxels of the shrunk grid all hold the same value (N4's histogram would have
// zero width: nothing to correct).
bool flat_in_mask(const FloatImage& image, const MaskImage& mask) {
    const float* v = image.GetBufferPointer();
    const unsigned char* m = mask.GetBufferPointer();
    const std::size_t count = image.GetBufferedRegion().GetNumberOfPixels();
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    for (std::size_t i = 0; i < count; ++i)
        if (m[i] != 0) {
            lo = std::min(lo, v[i]);
            hi = std::max(hi, v[i]);
        }
    return !(hi > lo);
}

// Thrown from N4's iteration observer to stop it when the caller's interrupt flag turns true.
struct Interrupted {};

// N4 on the shrunk image; returns its log-field control lattice.
ControlLattice::ConstPointer run_n4(const FloatImage::Pointer& image, const MaskImage::Pointer& mask, const ShrinkPlan& plan,
                                    const Vec3d& spacing, const BiasCorrectionOptions& o, BiasCorrectionReport& report,
                                    const std::atomic<bool>* interrupt) {
    auto n4 = N4Filter::New();
    n4->SetInput(image);
    n4->SetMaskImage(mask);
    n4->SetSplineOrder(3);
    N4Filter::ArrayType control_points;
    for (int a = 0; a < 3; ++a) {
        const double span_mm = (plan.dims[a] - 1) * plan.factors[a] * spacing[a];
        const int mesh = std::max(1, static_cast<int>(std::ceil(span_mm / o.spline_distance_mm - kMmMargin)));
        control_points[a] = static_cast<unsigned>(mesh + 3);
        report.control_points[a] = mesh + 3;
    }
    n4->SetNumberOfControlPoints(control_points);
    n4->SetNumberOfFittingLevels(static_cast<unsigned>(o.levels));
    N4Filter::VariableSizeArrayType iterations(static_cast<unsigned>(o.levels));
    iterations.Fill(static_cast<unsigned>(o.iterations));
    n4->SetMaximumNumberOfIterations(iterations);
    n4->SetConvergenceThreshold(static_cast<float>(o.convergence));
    n4->SetWienerFilterNoise(static_cast<float>(o.wiener_noise));
    n4->SetBiasFieldFullWidthAtHalfMaximum(static_cast<float>(o.fwhm));
    n4->SetNumberOfHistogramBins(static_cast<unsigned>(o.histogram_bins));
    report.level_iterations.assign(static_cast<std::size_t>(o.levels), 0);
    n4->AddObserver(itk::IterationEvent(), [&report, interrupt, raw = n4.GetPointer()](const itk::EventObject&) {
        report.level_iterations.at(raw->GetCurrentLevel()) = static_cast<int>(raw->GetElapsedIterations());
        report.final_convergence = raw->GetCurrentConvergenceMeasurement();
        if (interrupt != nullptr && interrupt->load()) throw Interrupted{};
    });
    n4->Update();
    return n4->GetLogBiasFieldControlPointLattice();
}

// The log field at every full-resolution voxel: the control lattice evaluated on a grid with the
// image's spacing spanning the shrunk grid's B-spline domain (plan.span voxels per axis, voxel i of
// it = image voxel i), cropped to the image (ITK's BSplineControlPointImageFilter's values).
Grid<float> full_resolution_log_field(const ControlLattice::ConstPointer& lattice, const ShrinkPlan& plan, const Lattice& grid) {
    const auto lattice_size = lattice->GetLargestPossibleRegion().GetSize();
    const Vec3i dims{static_cast<int>(lattice_size[0]), static_cast<int>(lattice_size[1]), static_cast<int>(lattice_size[2])};
    std::vector<float> control(lattice->GetLargestPossibleRegion().GetNumberOfPixels());
    const auto* points = lattice->GetBufferPointer();
    for (std::size_t i = 0; i < control.size(); ++i) control[i] = points[i][0];
    return evaluate_cubic_bspline(control, dims, plan.span, kIndexUnits, grid);
}

// image / exp(log field - mean log field over the fit mask), written over the log field (each
// voxel reads only its own: no third grid of the scan's size); the field's range in the mask.
Grid<float> divide_field(const Grid<float>& image, Grid<float> log_field, const Grid<std::uint8_t>& fit,
                         BiasCorrectionReport& report) {
    double sum = 0.0, lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    std::size_t count = 0;
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (fit[p] == 0) continue;
        const double v = log_field[p];
        sum += v;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        ++count;
    }
    const double mean = sum / static_cast<double>(count);
    report.field_min = std::exp(lo - mean);
    report.field_max = std::exp(hi - mean);
    // In float (expf: a quarter of exp's time, 1-2 ulps of the double quotient; the field is smooth
    // and its log within a few tenths of 0).
    const auto shift = static_cast<float>(mean);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, image.size(), 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
        const float* in = image.values().data();
        float* out = log_field.values().data();
        for (std::size_t i = r.begin(); i != r.end(); ++i) out[i] = in[i] * std::exp(shift - out[i]);
    });
    return log_field;
}

}  // namespace

void BiasCorrectionOptions::validate() const {
    check_option(shrink_mm, 0.0, 100.0, "shrink_mm");
    if (shrink_mm <= 0.0) fail("shrink_mm must be > 0");
    check_option(levels, 1, 8, "levels");
    check_option(iterations, 1, 10000, "iterations");
    check_option(convergence, 0.0, 1.0, "convergence");
    check_option(spline_distance_mm, 1.0, 10000.0, "spline_distance_mm");
    check_option(wiener_noise, 0.0, 1.0, "wiener_noise");
    if (wiener_noise <= 0.0) fail("wiener_noise must be > 0");
    check_option(fwhm, 0.001, 10.0, "fwhm");
    check_option(histogram_bins, 10, 100000, "histogram_bins");
}

Grid<float> correct_bias(const Grid<float>& image, const Grid<std::uint8_t>* mask, const BiasCorrectionOptions& options,
                         BiasCorrectionReport* report_out, const std::atomic<bool>* interrupt) {
    // N4 subsamples and fits on the index grid: the image is first put in the canonical axis order
    // (grid/reorient.hpp), so the same physical image stored with other axis orders (MINC read
    // back reversed, RAS- or LPS-ordered NIfTI) gets the same field.
    const AxisOrder order = canonical_order(image.lattice());
    if (!order.identity()) {
        check_inputs(image, mask);
        const std::optional<Grid<std::uint8_t>> m = mask ? std::optional(reorder(*mask, order)) : std::nullopt;
        const Grid<float> out = correct_bias(reorder(image, order), m ? &*m : nullptr, options, report_out, interrupt);
        return restore(out, order, image.lattice());
    }
    const auto start = Clock::now();
    options.validate();
    check_inputs(image, mask);
    BiasCorrectionReport report;
    const Grid<std::uint8_t> fit = fit_mask(image, mask, report);
    const Vec3d s = image.lattice().spacing();
    const ShrinkPlan plan = plan_shrink(image.dims(), s, options.shrink_mm);
    report.shrink_factors = plan.factors;
    report.shrunk_dims = plan.dims;
    const auto small = shrunk_image<FloatImage>(image.dims(), plan, [&](Vec3i p) {
        return options.denoise && fit(p) != 0 ? fit_median(image, fit, p) : image(p);
    });
    const auto small_mask = shrunk_image<MaskImage>(image.dims(), plan, [&](Vec3i p) { return fit(p); });
    const unsigned char* m = small_mask->GetBufferPointer();
    if (std::none_of(m, m + small_mask->GetBufferedRegion().GetNumberOfPixels(), [](unsigned char v) { return v != 0; }))
        fail("the mask leaves no voxel on the shrunk grid (" + dims_text(plan.dims) + "); lower shrink_mm");

    Grid<float> corrected;
    if (flat_in_mask(*small, *small_mask)) {
        report.level_iterations.clear();
        corrected = image;
    } else {
        const auto n4_start = Clock::now();
        use_tbb_work_units();
        ControlLattice::ConstPointer lattice;
        try {
            lattice = run_n4(small, small_mask, plan, s, options, report, interrupt);
        } catch (const Interrupted&) {
            report.interrupted = true;
        } catch (const itk::ExceptionObject& e) {
            throw std::runtime_error(std::string("bias correction: N4 failed: ") + e.GetDescription());
        }
        report.n4_ms = ms_since(n4_start);
        corrected = report.interrupted ? image : divide_field(image, full_resolution_log_field(lattice, plan, image.lattice()), fit, report);
    }
    report.ms = ms_since(start);
    if (report_out != nullptr) *report_out = std::move(report);
    return corrected;
}

double otsu_threshold(const Grid<float>& image) {
    if (image.size() == 0) fail("the image is empty");
    const auto values = image.values();
    if (std::any_of(values.begin(), values.end(), [](float v) { return !std::isfinite(v); }))
        fail("the image holds NaN or infinite voxels");
    const auto [lo_it, hi_it] = std::minmax_element(values.begin(), values.end());
    const double lo = *lo_it, hi = *hi_it;
    if (!(hi > lo)) return lo;
    constexpr int kBins = 256;
    const double width = (hi - lo) / kBins;
    std::array<double, kBins> count{};
    for (float v : values) count[static_cast<std::size_t>(std::min(kBins - 1, static_cast<int>((v - lo) / width)))] += 1.0;
    std::vector<double> counts(count.begin(), count.end()), centres(kBins);
    for (int b = 0; b < kBins; ++b) centres[static_cast<std::size_t>(b)] = b + 0.5;
    const int best_bin = static_cast<int>(otsu_split_bins(counts, centres, 2)[0]) - 1;  // last bin of the lower class
    return lo + (best_bin + 1) * width;
}

Grid<std::uint8_t> otsu_foreground(const Grid<float>& image) {
    const double t = otsu_threshold(image);
    Grid<std::uint8_t> fg(image.lattice(), 0);
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        fg[p] = image[p] >= t;
    }
    return fg;
}

}  // namespace liveset
