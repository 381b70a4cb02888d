// Milliseconds since a steady-clock time point: the one timer of the progress reports, the demos and the viewer.
#pragma once

#include <chrono>

namespace liveset {

inline double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace liveset
