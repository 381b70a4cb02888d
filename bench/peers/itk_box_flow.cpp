// Peer benchmark: ITK's sparse-field level set under pure mean curvature flow on the paper's box
// (a 50³ box centred in a 100³ lattice) until the box vanishes - liveset's `flow` / BM_BoxFlow.
//
// ITK only (no liveset code). φ0 is the exact signed distance to the box (negative inside; centre
// (n-1)/2, half size box/2, as liveset's make_box_field). The filter is
// ThresholdSegmentationLevelSetImageFilter with PropagationScaling 0, AdvectionScaling 0,
// CurvatureScaling 1 (so dφ/dt = κ|∇φ|, ITK's time step from its curvature CFL), MaximumRMSError 0.
// An IterationEvent observer timestamps every iteration and stops the filter once its active layer
// is empty (the box has vanished). One JSON line: iterations, median ms per iteration, total s.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include <itkCommand.h>
#include <itkImage.h>
#include <itkImageRegionIteratorWithIndex.h>
#include <itkMultiThreaderBase.h>
#include <itkThresholdSegmentationLevelSetImageFilter.h>

namespace {

using FloatImage = itk::Image<float, 3>;
using Clock = std::chrono::steady_clock;

// ITK's filter unchanged, plus a read-only look at its active layer size.
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

int int_arg(const std::string& k, const char* v, int lo, int hi) {
    char* end = nullptr;
    const long n = std::strtol(v, &end, 10);
    if (end == v || *end != '\0' || n < lo || n > hi) {
        std::cerr << "itk_box_flow: bad value for " << k << ": " << v << "\n";
        std::exit(2);
    }
    return static_cast<int>(n);
}

struct Ctx {
    Filter* filter;
    std::vector<Clock::time_point> stamps;
};

}  // namespace

int main(int argc, char** argv) {
    int lattice = 100, box = 50, threads = 1, max_iterations = 20000;
    int layers = 0;  // the sparse field's layers on each side; 0: the filter's default (the image dimension, 3)
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        if (i + 1 >= argc) {
            std::cerr << "usage: itk_box_flow [--lattice 100] [--box 50] [--threads 1] [--max-iterations 20000] [--layers N]\n";
            return 2;
        }
        if (k == "--lattice") lattice = int_arg(k, argv[++i], 4, 1024);
        else if (k == "--box") box = int_arg(k, argv[++i], 1, 1022);
        else if (k == "--threads") threads = int_arg(k, argv[++i], 1, 256);
        else if (k == "--max-iterations") max_iterations = int_arg(k, argv[++i], 1, 10'000'000);
        else if (k == "--layers") layers = int_arg(k, argv[++i], 0, 8);
        else {
            std::cerr << "itk_box_flow: unknown option " << k << "\n";
            return 2;
        }
    }
    if (box > lattice - 2) {
        std::cerr << "itk_box_flow: box must be at most lattice - 2\n";
        return 2;
    }
    itk::MultiThreaderBase::SetGlobalMaximumNumberOfThreads(threads);
    itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(threads);

    auto phi = FloatImage::New();
    FloatImage::RegionType region;
    region.SetSize({static_cast<itk::SizeValueType>(lattice), static_cast<itk::SizeValueType>(lattice),
                    static_cast<itk::SizeValueType>(lattice)});
    phi->SetRegions(region);
    phi->Allocate();
    auto feature = FloatImage::New();
    feature->SetRegions(region);
    feature->Allocate();
    feature->FillBuffer(0.0f);
    const double c = (lattice - 1) / 2.0, h = box / 2.0;
    for (itk::ImageRegionIteratorWithIndex<FloatImage> it(phi, region); !it.IsAtEnd(); ++it) {
        const auto idx = it.GetIndex();
        double q[3], out = 0;
        for (int a = 0; a < 3; ++a) {
            q[a] = std::abs(static_cast<double>(idx[a]) - c) - h;
            out += std::max(q[a], 0.0) * std::max(q[a], 0.0);
        }
        it.Set(static_cast<float>(std::sqrt(out) + std::min(std::max(q[0], std::max(q[1], q[2])), 0.0)));
    }

    auto filter = Filter::New();
    filter->SetInput(phi);
    filter->SetFeatureImage(feature);
    filter->SetLowerThreshold(-1.0);
    filter->SetUpperThreshold(1.0);
    filter->SetPropagationScaling(0.0);
    filter->SetAdvectionScaling(0.0);
    filter->SetCurvatureScaling(1.0);
    filter->SetMaximumRMSError(0.0);
    filter->SetNumberOfIterations(static_cast<itk::IdentifierType>(max_iterations));
    filter->SetNumberOfWorkUnits(static_cast<itk::ThreadIdType>(threads));
    if (layers > 0) filter->SetNumberOfLayers(static_cast<unsigned>(layers));  // else ImageDimension (3)

    Ctx ctx{filter.GetPointer(), {}};
    ctx.stamps.reserve(static_cast<std::size_t>(max_iterations) + 1);
    auto on_iter = itk::CStyleCommand::New();
    on_iter->SetClientData(&ctx);
    on_iter->SetCallback([](itk::Object*, const itk::EventObject&, void* p) {
        auto* x = static_cast<Ctx*>(p);
        x->stamps.push_back(Clock::now());
        if (x->filter->ActiveLayerSize() == 0) x->filter->SetNumberOfIterations(x->filter->GetElapsedIterations());
    });
    filter->AddObserver(itk::IterationEvent(), on_iter);
    const auto t0 = Clock::now();
    filter->Update();
    const double total_s = std::chrono::duration<double>(Clock::now() - t0).count();

    std::vector<double> ms;  // intervals between iterations (the first one also holds the set-up)
    for (std::size_t i = 1; i < ctx.stamps.size(); ++i)
        ms.push_back(std::chrono::duration<double, std::milli>(ctx.stamps[i] - ctx.stamps[i - 1]).count());
    std::sort(ms.begin(), ms.end());
    const double median = ms.empty() ? 0.0 : ms[ms.size() / 2];
    std::printf("{\"peer\":\"itk_box_flow\",\"lattice\":%d,\"box\":%d,\"layers\":%u,\"threads\":%d,\"iterations\":%lu,\"vanished\":%s,"
                "\"ms_per_iteration_median\":%.4f,\"total_s\":%.4f}\n",
                lattice, box, filter->GetNumberOfLayers(), threads, static_cast<unsigned long>(filter->GetElapsedIterations()),
                filter->ActiveLayerSize() == 0 ? "true" : "false", median, total_s);
    return 0;
}
