// `liveset view --headless --bench`: the frame-time breakdown of the paper's §5 scenarios on the
// loaded surface - static, agents moving (p = 0), agents repairing at p = 0.1 and 0.5 - with the
// 3D view filling the window: per frame the ms in level set, agents, meshing, upload and draw, the
// fragments rebuilt and the triangles drawn. Swarm: the demo's settings, but as in the paper's
// timing experiment every agent may edit (no edit range) and raises or lowers the surface at random
// with probability p per step.
#pragma once

#include <optional>
#include <string>

#include "viewer.hpp"

namespace liveset::viewer {

struct BenchOptions {
    int frames = 100;                 // measured frames per scenario (after 5 warm-up frames)
    std::size_t agents = 200;
    std::optional<Vec3d> target;      // default: the surface point nearest the top of the surface
    bool json = false;
    std::string mode = "frames";      // frames | segment | interaction (bench_modes.cpp)
    std::string renderer;             // the OpenGL renderer and EGL platform, reported with the figures
};

int run_bench(Viewer& viewer, const BenchOptions& options, int width, int height);
int run_segment_bench(Viewer& viewer, const BenchOptions& options, int width, int height);
int run_interaction_bench(Viewer& viewer, const BenchOptions& options, int width, int height);

}  // namespace liveset::viewer
