// CLI plumbing shared by the image commands: seed parsing (`I,J,K[:R]`, `X,Y,Z[:R]` in mm),
// output-path checks done before long runs, a terminal progress line, and Ctrl-C handling that
// lets a run stop cleanly without writing anything.
#pragma once

#include <atomic>
#include <chrono>
#include <string>
#include <vector>

#include "liveset/grid/lattice.hpp"
#include "liveset/segment/intensity.hpp"

namespace liveset::cli {

// "I,J,K" or "I,J,K:R" (voxel indices, radius in voxels; default radius `default_radius`).
SeedBall parse_seed_voxel(const std::string& text, double default_radius);
// "X,Y,Z" or "X,Y,Z:R" in physical (LPS, mm) coordinates, radius in mm -> index space.
SeedBall parse_seed_mm(const std::string& text, const Lattice& lattice, double default_radius_mm);
// Throws UsageError when the seed centre lies outside the image.
void check_seed_inside(const SeedBall& seed, const Lattice& lattice, const std::string& given_as);

enum class OutputKind { kImage, kMesh, kText };
// Fails fast (UsageError) if `path` cannot be written later: folder missing or not writable, the
// path is a folder, or the extension is not one the writer knows.
void check_output_path(const std::string& path, OutputKind kind, const std::string& option);

// Installs a SIGINT/SIGTERM handler for its lifetime; interrupted() turns true on Ctrl-C. Guards
// nest: a command installs one before reading its inputs, so a Ctrl-C at any time is seen.
class InterruptGuard {
public:
    InterruptGuard();
    ~InterruptGuard();
    InterruptGuard(const InterruptGuard&) = delete;
    InterruptGuard& operator=(const InterruptGuard&) = delete;
    const std::atomic<bool>& flag() const;
    bool interrupted() const { return flag().load(); }
};

// One self-overwriting status line on stderr, only when stderr is a terminal and not quiet;
// updates at most 10 times a second.
class ProgressLine {
public:
    explicit ProgressLine(bool quiet);
    ~ProgressLine();
    void update(const std::string& text, bool force = false);
    void finish();
    bool active() const { return enabled_; }

private:
    bool enabled_ = false;
    bool dirty_ = false;
    std::chrono::steady_clock::time_point last_{};
};

}  // namespace liveset::cli
