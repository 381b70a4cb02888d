// Peer benchmark: ITK's ThresholdSegmentationLevelSetImageFilter on the BrainWeb grey-matter task.
//
// This program uses ITK only (no liveset code): it is the reference point liveset is compared with.
// It reads the T1 image, the brain mask and the crisp labels; builds the initial level set from the
// same seed balls liveset uses (voxel indices, radius in voxels); runs ITK's sparse-field threshold
// level set with the intensity window [lower, upper] (raw units); times every iteration with an
// itk::IterationEvent observer; thresholds the output at 0 (ITK convention: phi < 0 inside),
// intersects it with the brain mask, and scores grey matter (labels == 2) by Dice. One JSON line.
//
// Speed correspondence (see docs/peers/itk_threshold_levelset.md):
//   liveset (paper Eq. 1-3):  dphi/dt = |grad phi| * 1/2 * ((1 - a) D(I) + a * kappa),
//                             D(I) = 2|mu - I|^n / (eps^n + |mu - I|^n) - 1   (n = 2, D < 0 inside)
//   ITK:                      dphi/dt = w_c * kappa * |grad phi| - w_p * G(I) * |grad phi|,
//                             G(I) = I - L (I < mid), U - I (otherwise)        (G > 0 inside)
//   with kappa = div(grad phi / |grad phi|) in both. With L = mu - eps, U = mu + eps, G / eps and -D
//   agree at I = mu (1), at the window edges (0) and in slope there (1/eps, for n = 2); D saturates at
//   +1 far from the window while G / eps keeps falling linearly. So (1 - a) : a on the normalised
//   feature is w_p : w_c = (1 - a) : a * eps_raw. ITK picks its time step from the largest
//   propagation and curvature changes on the active layer, so only that ratio matters.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <itkCommand.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkImageRegionConstIterator.h>
#include <itkImageRegionIterator.h>
#include <itkImageRegionIteratorWithIndex.h>
#include <itkMetaImageIOFactory.h>
#include <itkMultiThreaderBase.h>
#include <itkNiftiImageIOFactory.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>
#include <itkThresholdSegmentationLevelSetImageFilter.h>

namespace {

constexpr unsigned kDim = 3;
using FloatImage = itk::Image<float, kDim>;
using ByteImage = itk::Image<std::uint8_t, kDim>;
using LabelImage = itk::Image<std::int16_t, kDim>;
using Clock = std::chrono::steady_clock;

// ITK's filter unchanged, plus a read-only look at the size of its active layer (the zero level
// set's voxel list, m_Layers[0]) so per-iteration costs can be compared at equal front sizes.
class Filter : public itk::ThresholdSegmentationLevelSetImageFilter<FloatImage, FloatImage, float> {
public:
    ITK_DISALLOW_COPY_AND_MOVE(Filter);
    using Self = Filter;
    using Superclass = itk::ThresholdSegmentationLevelSetImageFilter<FloatImage, FloatImage, float>;
    using Pointer = itk::SmartPointer<Self>;
    itkNewMacro(Self);
    std::size_t ActiveLayerSize() const { return this->m_Layers.empty() ? 0 : this->m_Layers[0]->Size(); }

protected:
    Filter() = default;
    ~Filter() override = default;
};

struct Seed {
    double c[3];
    double r;
};

struct Args {
    std::string image, mask, labels, out_mask, log;
    std::vector<Seed> seeds;
    double seed_radius = 2.0;
    double lower = 72.0, upper = 116.0;  // raw window: mu - eps, mu + eps (mu 94, eps 22)
    double alpha = 0.1;
    double propagation = std::numeric_limits<double>::quiet_NaN();  // default (1 - alpha)
    double curvature = std::numeric_limits<double>::quiet_NaN();    // default alpha * eps_raw
    bool naive_weights = false;  // w_p = 1 - alpha, w_c = alpha with no unit correction
    unsigned iterations = 1000;
    double rms = 0.001;
    unsigned threads = 1;
    int label = 2;
    unsigned layers = 0;  // the sparse field's layers on each side; 0: the filter's default (the image dimension)
    std::string init = "sdf";  // sdf: exact distance to the seed spheres; maurer: SignedMaurer of the balls
    std::vector<unsigned> checkpoints;
};

[[noreturn]] void usage(const std::string& msg) {
    std::cerr << "itk_threshold_levelset: " << msg << "\n"
              << "usage: itk_threshold_levelset --image T1 --mask BRAIN_MASK --labels LABELS --seed I,J,K[:R] ...\n"
                 "  [--seed-radius 2] [--lower 72] [--upper 116] [--alpha 0.1] [--propagation W] [--curvature W]\n"
                 "  [--naive-weights] [--iterations 1000] [--rms 0.001] [--threads 1] [--label 2] [--layers N]\n"
                 "  [--init sdf|maurer] [--checkpoints 50,200,...] [--out-mask FILE] [--log FILE.jsonl]\n";
    std::exit(2);
}

std::vector<double> split_numbers(const std::string& s) {
    std::vector<double> v;
    std::stringstream ss(s);
    std::string tok;
    while (std::getline(ss, tok, ',')) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(tok, &used);
        } catch (const std::exception&) {
            usage("bad number list '" + s + "'");
        }
        if (used != tok.size() || !std::isfinite(x)) usage("bad number list '" + s + "'");
        v.push_back(x);
    }
    return v;
}

double to_double(const std::string& s) {
    const auto v = split_numbers(s);
    if (v.size() != 1) usage("expected one number, got '" + s + "'");
    return v[0];
}

// A whole number in [lo, hi] (checked before the conversion, which is undefined out of range).
long to_whole(const std::string& name, const std::string& s, long lo, long hi) {
    const double x = to_double(s);
    if (!(x >= static_cast<double>(lo) && x <= static_cast<double>(hi)) || x != std::floor(x))
        usage(name + " must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + s + "'");
    return static_cast<long>(x);
}

Args parse(int argc, char** argv) {
    Args a;
    std::vector<std::string> seed_text;
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        auto val = [&]() -> std::string {
            if (i + 1 >= argc) usage("missing value after " + k);
            return argv[++i];
        };
        if (k == "--image") a.image = val();
        else if (k == "--mask") a.mask = val();
        else if (k == "--labels") a.labels = val();
        else if (k == "--out-mask") a.out_mask = val();
        else if (k == "--log") a.log = val();
        else if (k == "--seed") seed_text.push_back(val());
        else if (k == "--seed-radius") a.seed_radius = to_double(val());
        else if (k == "--lower") a.lower = to_double(val());
        else if (k == "--upper") a.upper = to_double(val());
        else if (k == "--alpha") a.alpha = to_double(val());
        else if (k == "--propagation") a.propagation = to_double(val());
        else if (k == "--curvature") a.curvature = to_double(val());
        else if (k == "--naive-weights") a.naive_weights = true;
        else if (k == "--iterations") a.iterations = static_cast<unsigned>(to_whole(k, val(), 1, 10'000'000));
        else if (k == "--rms") a.rms = to_double(val());
        else if (k == "--threads") a.threads = static_cast<unsigned>(to_whole(k, val(), 1, 256));
        else if (k == "--label") a.label = static_cast<int>(to_whole(k, val(), 0, 255));
        else if (k == "--layers") a.layers = static_cast<unsigned>(to_whole(k, val(), 0, 8));  // 0: the filter's default
        else if (k == "--init") a.init = val();
        else if (k == "--checkpoints") {
            for (double x : split_numbers(val())) {
                if (!(x >= 1 && x <= 1e7) || x != std::floor(x)) usage("--checkpoints must be whole iteration numbers");
                a.checkpoints.push_back(static_cast<unsigned>(x));
            }
        } else if (k == "-h" || k == "--help") usage("help");
        else usage("unknown argument " + k);
    }
    if (a.image.empty() || a.mask.empty() || a.labels.empty()) usage("--image, --mask and --labels are required");
    if (seed_text.empty()) usage("at least one --seed is required");
    if (!(a.upper > a.lower)) usage("--upper must exceed --lower");
    if (!(a.alpha >= 0 && a.alpha < 1)) usage("--alpha must be in [0, 1)");
    if (a.init != "sdf" && a.init != "maurer") usage("--init must be sdf or maurer");
    for (const auto& t : seed_text) {
        const auto colon = t.find(':');
        const auto c = split_numbers(t.substr(0, colon));
        if (c.size() != 3) usage("seed must be I,J,K[:R], got '" + t + "'");
        Seed s{{c[0], c[1], c[2]}, a.seed_radius};
        if (colon != std::string::npos) s.r = to_double(t.substr(colon + 1));
        if (!(s.r > 0)) usage("seed radius must be positive");
        a.seeds.push_back(s);
    }
    const double eps = 0.5 * (a.upper - a.lower);
    if (std::isnan(a.propagation)) a.propagation = 1.0 - a.alpha;
    if (std::isnan(a.curvature)) a.curvature = a.naive_weights ? a.alpha : a.alpha * eps;
    std::sort(a.checkpoints.begin(), a.checkpoints.end());
    return a;
}

template <typename TImage>
typename TImage::Pointer read(const std::string& path) {
    auto reader = itk::ImageFileReader<TImage>::New();
    reader->SetFileName(path);
    reader->Update();
    return reader->GetOutput();
}

template <typename A, typename B>
void require_same_grid(const A* a, const B* b, const std::string& what) {
    if (a->GetLargestPossibleRegion().GetSize() != b->GetLargestPossibleRegion().GetSize()) {
        std::ostringstream os;
        os << what << " size " << b->GetLargestPossibleRegion().GetSize() << " does not match the image "
           << a->GetLargestPossibleRegion().GetSize();
        throw std::runtime_error(os.str());
    }
}

// Dice of (phi < 0) AND mask against labels == label, voxel by voxel in buffer order.
struct Overlap {
    double dice = 0;
    std::uint64_t segmented = 0, truth = 0, both = 0;
};

Overlap dice(const FloatImage* phi, const ByteImage* mask, const LabelImage* labels, int label) {
    const std::size_t n = phi->GetLargestPossibleRegion().GetNumberOfPixels();
    const float* p = phi->GetBufferPointer();
    const std::uint8_t* m = mask->GetBufferPointer();
    const std::int16_t* l = labels->GetBufferPointer();
    Overlap o;
    for (std::size_t i = 0; i < n; ++i) {
        const bool s = p[i] < 0.0f && m[i] != 0;
        const bool t = l[i] == label;
        o.segmented += s;
        o.truth += t;
        o.both += s && t;
    }
    o.dice = (o.segmented + o.truth) ? 2.0 * static_cast<double>(o.both) / static_cast<double>(o.segmented + o.truth) : 1.0;
    return o;
}

double median(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    double m = v[mid];
    if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
    return m;
}

}  // namespace

int main(int argc, char** argv) try {
    const Args a = parse(argc, argv);
    itk::NiftiImageIOFactory::RegisterOneFactory();
    itk::MetaImageIOFactory::RegisterOneFactory();
    itk::MultiThreaderBase::SetGlobalMaximumNumberOfThreads(std::max(a.threads, 1u));
    itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(a.threads);

    FloatImage::Pointer t1 = read<FloatImage>(a.image);
    ByteImage::Pointer mask = read<ByteImage>(a.mask);
    LabelImage::Pointer labels = read<LabelImage>(a.labels);
    require_same_grid(t1.GetPointer(), mask.GetPointer(), "brain mask");
    require_same_grid(t1.GetPointer(), labels.GetPointer(), "label image");
    const auto size = t1->GetLargestPossibleRegion().GetSize();

    // Feature image: the raw T1 inside the brain mask; outside, the value lower - eps so that ITK's
    // feature is G = -eps there (the counterpart of liveset's D = +1, pure contraction, in its ROI).
    const double eps = 0.5 * (a.upper - a.lower);
    auto feature = FloatImage::New();
    feature->CopyInformation(t1);
    feature->SetRegions(t1->GetLargestPossibleRegion());
    feature->Allocate();
    {
        const std::size_t n = t1->GetLargestPossibleRegion().GetNumberOfPixels();
        const float* src = t1->GetBufferPointer();
        const std::uint8_t* m = mask->GetBufferPointer();
        float* dst = feature->GetBufferPointer();
        for (std::size_t i = 0; i < n; ++i) dst[i] = m[i] ? src[i] : static_cast<float>(a.lower - eps);
    }

    // Initial level set, negative inside the seed balls (ITK's convention for this filter family).
    auto init = FloatImage::New();
    init->CopyInformation(t1);
    init->SetRegions(t1->GetLargestPossibleRegion());
    init->Allocate();
    double iso = 0.0;
    if (a.init == "sdf") {
        // Exact signed distance (voxel units) to the union of the seed spheres, as liveset builds it.
        itk::ImageRegionIteratorWithIndex<FloatImage> it(init, init->GetLargestPossibleRegion());
        for (it.GoToBegin(); !it.IsAtEnd(); ++it) {
            const auto idx = it.GetIndex();
            double d = std::numeric_limits<double>::max();
            for (const Seed& s : a.seeds) {
                const double dx = static_cast<double>(idx[0]) - s.c[0], dy = static_cast<double>(idx[1]) - s.c[1],
                             dz = static_cast<double>(idx[2]) - s.c[2];
                d = std::min(d, std::sqrt(dx * dx + dy * dy + dz * dz) - s.r);
            }
            it.Set(static_cast<float>(d));
        }
    } else {
        // Seed-ball mask (voxels within r of a centre) -> SignedMaurerDistanceMap (inside negative;
        // object boundary voxels are 0 and their outside neighbours 1: the front is the 0.5 isosurface).
        auto balls = ByteImage::New();
        balls->CopyInformation(t1);
        balls->SetRegions(t1->GetLargestPossibleRegion());
        balls->Allocate();
        itk::ImageRegionIteratorWithIndex<ByteImage> it(balls, balls->GetLargestPossibleRegion());
        for (it.GoToBegin(); !it.IsAtEnd(); ++it) {
            const auto idx = it.GetIndex();
            bool in = false;
            for (const Seed& s : a.seeds) {
                const double dx = static_cast<double>(idx[0]) - s.c[0], dy = static_cast<double>(idx[1]) - s.c[1],
                             dz = static_cast<double>(idx[2]) - s.c[2];
                in = in || std::sqrt(dx * dx + dy * dy + dz * dz) <= s.r;
            }
            it.Set(in ? 1 : 0);
        }
        auto maurer = itk::SignedMaurerDistanceMapImageFilter<ByteImage, FloatImage>::New();
        maurer->SetInput(balls);
        maurer->SetInsideIsPositive(false);
        maurer->SetSquaredDistance(false);
        maurer->SetUseImageSpacing(false);
        maurer->SetBackgroundValue(0);
        maurer->Update();
        init = maurer->GetOutput();
        init->DisconnectPipeline();
        iso = 0.5;
    }

    auto filter = Filter::New();
    filter->SetInput(init);
    filter->SetFeatureImage(feature);
    filter->SetLowerThreshold(static_cast<float>(a.lower));
    filter->SetUpperThreshold(static_cast<float>(a.upper));
    filter->SetEdgeWeight(0.0);
    filter->SetPropagationScaling(static_cast<float>(a.propagation));
    filter->SetCurvatureScaling(static_cast<float>(a.curvature));
    filter->SetAdvectionScaling(0.0);
    filter->SetIsoSurfaceValue(static_cast<float>(iso));
    filter->SetMaximumRMSError(a.rms);
    filter->SetNumberOfIterations(a.iterations);
    filter->SetNumberOfWorkUnits(a.threads);
    if (a.layers > 0) filter->SetNumberOfLayers(a.layers);  // else ImageDimension (3), the segmentation filters' default

    // Iteration observer: a timestamp per IterationEvent; at checkpoints, the Dice of the current
    // output (the sparse field updates the output buffer in place; its sign is valid everywhere).
    std::vector<Clock::time_point> stamps;
    stamps.reserve(a.iterations + 1);
    std::vector<std::size_t> layer;  // active-layer size after each iteration
    std::vector<double> rms;         // RMS change of each iteration
    layer.reserve(a.iterations + 1);
    rms.reserve(a.iterations + 1);
    Clock::time_point t_start{};
    double checkpoint_s = 0;
    std::vector<std::pair<unsigned, Overlap>> checkpoint_dice;
    std::size_t next_checkpoint = 0;
    auto on_start = itk::CStyleCommand::New();
    auto on_iter = itk::CStyleCommand::New();
    struct Ctx {
        std::vector<Clock::time_point>* stamps;
        std::vector<std::size_t>* layer;
        std::vector<double>* rms;
        Clock::time_point* t_start;
        double* checkpoint_s;
        std::vector<std::pair<unsigned, Overlap>>* out;
        std::size_t* next;
        const Args* args;
        const ByteImage* mask;
        const LabelImage* labels;
        Filter* filter;
    } ctx{&stamps, &layer, &rms, &t_start, &checkpoint_s, &checkpoint_dice, &next_checkpoint, &a, mask.GetPointer(), labels.GetPointer(),
          filter.GetPointer()};
    on_start->SetClientData(&ctx);
    on_start->SetCallback([](itk::Object*, const itk::EventObject&, void* p) { *static_cast<Ctx*>(p)->t_start = Clock::now(); });
    on_iter->SetClientData(&ctx);
    on_iter->SetCallback([](itk::Object*, const itk::EventObject&, void* p) {
        auto* c = static_cast<Ctx*>(p);
        const auto now = Clock::now();
        c->stamps->push_back(now);
        c->layer->push_back(c->filter->ActiveLayerSize());
        c->rms->push_back(c->filter->GetRMSChange());
        const unsigned it = static_cast<unsigned>(c->filter->GetElapsedIterations());
        while (*c->next < c->args->checkpoints.size() && c->args->checkpoints[*c->next] < it) ++*c->next;
        if (*c->next < c->args->checkpoints.size() && c->args->checkpoints[*c->next] == it) {
            c->out->emplace_back(it, dice(c->filter->GetOutput(), c->mask, c->labels, c->args->label));
            ++*c->next;
            const auto after = Clock::now();
            *c->checkpoint_s += std::chrono::duration<double>(after - now).count();
            c->stamps->back() = after;  // keep the Dice work out of the next iteration's interval
        }
    });
    filter->AddObserver(itk::StartEvent(), on_start);
    filter->AddObserver(itk::IterationEvent(), on_iter);

    const auto t0 = Clock::now();
    filter->Update();
    const auto t1_end = Clock::now();

    // Per-iteration times: the intervals between consecutive IterationEvents (the first iteration
    // shares its interval with the speed image and sparse-field set-up, reported as setup_s).
    std::vector<double> ms;
    for (std::size_t i = 1; i < stamps.size(); ++i)
        ms.push_back(std::chrono::duration<double, std::milli>(stamps[i] - stamps[i - 1]).count());
    const double total_s = std::chrono::duration<double>(t1_end - t0).count() - checkpoint_s;
    const double setup_s =
        stamps.empty() ? total_s : std::chrono::duration<double>(stamps.front() - t0).count() - median(ms) / 1000.0;
    double iterate_s = 0;
    for (double x : ms) iterate_s += x / 1000.0;

    // Cost per active-layer voxel: interval i (iteration i + 1) works on the layer left by iteration i.
    std::vector<double> ns_per_voxel;
    for (std::size_t i = 0; i < ms.size(); ++i)
        if (layer[i] > 0) ns_per_voxel.push_back(1e6 * ms[i] / static_cast<double>(layer[i]));
    if (!a.log.empty()) {
        std::FILE* f = std::fopen(a.log.c_str(), "w");
        if (!f) throw std::runtime_error("cannot write " + a.log);
        for (std::size_t i = 0; i < stamps.size(); ++i) {
            std::fprintf(f, "{\"iteration\":%zu,\"active_layer\":%zu,\"rms_change\":%.6g", i + 1, layer[i], rms[i]);
            if (i > 0) std::fprintf(f, ",\"ms\":%.4f", ms[i - 1]);
            std::fprintf(f, "}\n");
        }
        std::fclose(f);
    }

    FloatImage::Pointer phi = filter->GetOutput();
    const Overlap o = dice(phi.GetPointer(), mask.GetPointer(), labels.GetPointer(), a.label);
    const unsigned iterations = static_cast<unsigned>(filter->GetElapsedIterations());

    if (!a.out_mask.empty()) {
        auto out = ByteImage::New();
        out->CopyInformation(t1);
        out->SetRegions(t1->GetLargestPossibleRegion());
        out->Allocate();
        const std::size_t n = t1->GetLargestPossibleRegion().GetNumberOfPixels();
        for (std::size_t i = 0; i < n; ++i)
            out->GetBufferPointer()[i] = phi->GetBufferPointer()[i] < 0.0f && mask->GetBufferPointer()[i] != 0;
        auto writer = itk::ImageFileWriter<ByteImage>::New();
        writer->SetFileName(a.out_mask);
        writer->SetInput(out);
        writer->UseCompressionOn();
        writer->Update();
    }

    std::printf("{\"peer\":\"itk::ThresholdSegmentationLevelSetImageFilter\",\"itk_version\":\"%s\",", ITK_VERSION_STRING);
    std::printf("\"iterations\":%u,\"max_iterations\":%u,\"stop\":\"%s\",\"rms_change\":%.6g,\"max_rms_error\":%.6g,", iterations,
                a.iterations, iterations < a.iterations ? "rms" : "iterations", filter->GetRMSChange(), a.rms);
    std::printf("\"ms_per_iteration_median\":%.4f,\"ms_per_iteration_mean\":%.4f,", median(ms),
                ms.empty() ? 0.0 : 1000.0 * iterate_s / static_cast<double>(ms.size()));
    std::printf("\"active_layer\":%zu,\"ns_per_active_voxel_median\":%.2f,", layer.empty() ? std::size_t{0} : layer.back(),
                median(ns_per_voxel));
    std::printf("\"total_s\":%.3f,\"setup_s\":%.3f,\"iterate_s\":%.3f,", total_s, setup_s, iterate_s);
    std::printf("\"dice\":%.4f,\"segmented_voxels\":%llu,\"truth_voxels\":%llu,", o.dice,
                static_cast<unsigned long long>(o.segmented), static_cast<unsigned long long>(o.truth));
    std::printf("\"layers\":%u,", filter->GetNumberOfLayers());
    std::printf("\"threads\":%u,\"lower\":%g,\"upper\":%g,\"alpha\":%g,\"curvature_scaling\":%g,\"propagation_scaling\":%g,",
                a.threads, a.lower, a.upper, a.alpha, static_cast<double>(filter->GetCurvatureScaling()),
                static_cast<double>(filter->GetPropagationScaling()));
    std::printf("\"init\":\"%s\",\"seeds\":%zu,\"seed_radius\":%g,\"size\":[%lu,%lu,%lu],\"checkpoints\":[", a.init.c_str(),
                a.seeds.size(), a.seed_radius, static_cast<unsigned long>(size[0]), static_cast<unsigned long>(size[1]),
                static_cast<unsigned long>(size[2]));
    for (std::size_t i = 0; i < checkpoint_dice.size(); ++i)
        std::printf("%s{\"iteration\":%u,\"dice\":%.4f,\"segmented_voxels\":%llu}", i ? "," : "", checkpoint_dice[i].first,
                    checkpoint_dice[i].second.dice, static_cast<unsigned long long>(checkpoint_dice[i].second.segmented));
    std::printf("]}\n");
    return 0;
} catch (const std::exception& e) {
    std::cerr << "itk_threshold_levelset: " << e.what() << "\n";
    return 1;
}
