// Peer benchmark: VTK's vtkFlyingEdges3D (and vtkMarchingCubes) meshing a φ image at isovalue 0.
//
// This program uses VTK only (no liveset code): the reference point for liveset's whole-volume
// marching cubes (`marching_cubes_slabs`, bench/mesh_file_bench.cpp). It reads a φ image (.nii,
// .nii.gz via vtkNIFTIImageReader; .mha/.mhd via vtkMetaImageReader) as float, sets the SMP backend
// (TBB or STDThread) and its thread count explicitly, and times `Update()` of a freshly modified
// filter --reps times (reading excluded). Normals are computed (liveset computes them too), scalars
// are not. One JSON line: median/min wall ms, median process CPU ms, triangles, points, backend, threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <ctime>
#include <vector>

#include <vtkFlyingEdges3D.h>
#include <vtkImageAlgorithm.h>
#include <vtkImageCast.h>
#include <vtkImageData.h>
#include <vtkMarchingCubes.h>
#include <vtkMetaImageReader.h>
#include <vtkNIFTIImageReader.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>

namespace {

struct Args {
    std::string phi, backend = "TBB", algo = "fe";
    int threads = 1, reps = 7;
    bool normals = true;
};

[[noreturn]] void usage(const std::string& msg) {
    std::cerr << "vtk_flying_edges: " << msg
              << "\nusage: vtk_flying_edges --phi FILE [--threads N] [--reps R] [--backend TBB|STDThread|Sequential]"
                 " [--algo fe|mc] [--no-normals]\n";
    std::exit(2);
}

Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage("missing value for " + k);
            return argv[++i];
        };
        auto integer = [&](int lo) {
            const std::string v = value();
            char* end = nullptr;
            const long n = std::strtol(v.c_str(), &end, 10);
            if (end == v.c_str() || *end != '\0' || n < lo || n > 1024) usage("bad value for " + k + ": " + v);
            return static_cast<int>(n);
        };
        if (k == "--phi") a.phi = value();
        else if (k == "--threads") a.threads = integer(1);
        else if (k == "--reps") a.reps = integer(1);
        else if (k == "--backend") a.backend = value();
        else if (k == "--algo") a.algo = value();
        else if (k == "--no-normals") a.normals = false;
        else usage("unknown option " + k);
    }
    if (a.phi.empty()) usage("--phi is required");
    if (a.algo != "fe" && a.algo != "mc") usage("--algo must be fe or mc");
    return a;
}

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

vtkSmartPointer<vtkImageData> read_phi(const std::string& path) {
    vtkSmartPointer<vtkImageAlgorithm> reader;
    if (ends_with(path, ".nii") || ends_with(path, ".nii.gz")) {
        auto r = vtkSmartPointer<vtkNIFTIImageReader>::New();
        r->SetFileName(path.c_str());
        reader = r;
    } else if (ends_with(path, ".mha") || ends_with(path, ".mhd")) {
        auto r = vtkSmartPointer<vtkMetaImageReader>::New();
        r->SetFileName(path.c_str());
        reader = r;
    } else {
        usage("unsupported image type (use .nii, .nii.gz, .mha or .mhd): " + path);
    }
    vtkNew<vtkImageCast> cast;
    cast->SetInputConnection(reader->GetOutputPort());
    cast->SetOutputScalarTypeToFloat();
    cast->Update();
    vtkImageData* out = cast->GetOutput();
    int dims[3];
    out->GetDimensions(dims);
    if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2) {
        std::cerr << "vtk_flying_edges: cannot read a 3-D image from " << path << "\n";
        std::exit(1);
    }
    auto copy = vtkSmartPointer<vtkImageData>::New();
    copy->DeepCopy(out);
    return copy;
}

// CPU time of the whole process (all threads), ms: with one thread, the cost without the load's
// preemption.
double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double median_of(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
    const Args a = parse(argc, argv);
    vtkSMPTools::SetBackend(a.backend.c_str());
    if (a.backend != vtkSMPTools::GetBackend()) usage("SMP backend " + a.backend + " not available in this VTK");
    vtkSMPTools::Initialize(a.threads);
    const vtkSmartPointer<vtkImageData> phi = read_phi(a.phi);
    int dims[3];
    phi->GetDimensions(dims);

    vtkSmartPointer<vtkPolyDataAlgorithm> filter;
    if (a.algo == "fe") {
        auto fe = vtkSmartPointer<vtkFlyingEdges3D>::New();
        fe->SetComputeNormals(a.normals);
        fe->SetComputeGradients(false);
        fe->SetComputeScalars(false);
        fe->SetValue(0, 0.0);
        filter = fe;
    } else {
        auto mc = vtkSmartPointer<vtkMarchingCubes>::New();
        mc->SetComputeNormals(a.normals);
        mc->SetComputeGradients(false);
        mc->SetComputeScalars(false);
        mc->SetValue(0, 0.0);
        filter = mc;
    }
    filter->SetInputData(phi);
    std::vector<double> ms, cpu_ms;
    for (int r = 0; r < a.reps; ++r) {
        filter->Modified();
        const double c0 = process_cpu_ms();
        const auto t0 = std::chrono::steady_clock::now();
        filter->Update();
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        cpu_ms.push_back(process_cpu_ms() - c0);
    }
    std::vector<double> sorted = ms;
    std::sort(sorted.begin(), sorted.end());
    const double median = median_of(ms), cpu_median = median_of(cpu_ms);
    vtkPolyData* out = filter->GetOutput();
    std::printf(
        "{\"peer\":\"%s\",\"phi\":\"%s\",\"dims\":[%d,%d,%d],\"backend\":\"%s\",\"threads\":%d,\"vtk_threads\":%d,"
        "\"reps\":%d,\"median_ms\":%.3f,\"min_ms\":%.3f,\"cpu_median_ms\":%.3f,\"triangles\":%lld,\"points\":%lld,\"normals\":%s}\n",
        a.algo == "fe" ? "vtkFlyingEdges3D" : "vtkMarchingCubes", a.phi.c_str(), dims[0], dims[1], dims[2],
        vtkSMPTools::GetBackend(), a.threads, vtkSMPTools::GetEstimatedNumberOfThreads(), a.reps, median, sorted.front(), cpu_median,
        static_cast<long long>(out->GetNumberOfPolys()), static_cast<long long>(out->GetNumberOfPoints()),
        a.normals ? "true" : "false");
    return 0;
}
