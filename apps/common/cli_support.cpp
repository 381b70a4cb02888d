// Seed parsing, output checks, Ctrl-C handling and the progress line.
#include "cli_support.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <sstream>

#include "cli_common.hpp"
#include "liveset/mesh/mesh_io.hpp"

namespace liveset::cli {

namespace {

std::atomic<bool> g_interrupted{false};
int g_guard_depth = 0;  // nested guards share one handler and one flag

extern "C" void on_signal(int) { g_interrupted.store(true); }

std::vector<double> parse_numbers(const std::string& text, const std::string& what) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) {
        try {
            std::size_t used = 0;
            const double x = std::stod(item, &used);
            if (used != item.size() || !std::isfinite(x)) throw std::invalid_argument(item);
            v.push_back(x);
        } catch (const std::exception&) {
            throw UsageError(fmt::format("bad {} '{}': expected numbers like 10,20,30 or 10,20,30:2", what, text));
        }
    }
    if (v.size() != 3 || (!text.empty() && text.back() == ','))
        throw UsageError(fmt::format("bad {} '{}': expected three comma-separated coordinates", what, text));
    return v;
}

// Splits "a,b,c[:r]" into the coordinate part and an optional radius.
std::pair<std::string, double> split_radius(const std::string& text, double default_radius, const std::string& what) {
    const auto colon = text.find(':');
    if (colon == std::string::npos) return {text, default_radius};
    const std::string r = text.substr(colon + 1);
    try {
        std::size_t used = 0;
        const double radius = std::stod(r, &used);
        if (used != r.size() || !std::isfinite(radius) || radius <= 0 || radius > 1000) throw std::invalid_argument(r);
        return {text.substr(0, colon), radius};
    } catch (const std::exception&) {
        throw UsageError(fmt::format("bad {} radius in '{}': expected a positive number after ':'", what, text));
    }
}

}  // namespace

SeedBall parse_seed_voxel(const std::string& text, double default_radius) {
    const auto [coords, r] = split_radius(text, default_radius, "seed");
    const std::vector<double> v = parse_numbers(coords, "seed");
    return {{v[0], v[1], v[2]}, r};
}

SeedBall parse_seed_mm(const std::string& text, const Lattice& lattice, double default_radius_mm) {
    const auto [coords, r] = split_radius(text, default_radius_mm, "seed");
    const std::vector<double> v = parse_numbers(coords, "seed");
    const Vec3d s = lattice.spacing();
    return {lattice.to_index({v[0], v[1], v[2]}), r / std::min({s.x, s.y, s.z})};
}

void check_seed_inside(const SeedBall& seed, const Lattice& lattice, const std::string& given_as) {
    if (!lattice.contains(seed.center)) {
        const Vec3i d = lattice.dims();
        throw UsageError(fmt::format("seed {} lies outside the image (voxel ({:.1f}, {:.1f}, {:.1f}); the image has {}x{}x{} voxels)",
                                     given_as, seed.center.x, seed.center.y, seed.center.z, d.x, d.y, d.z));
    }
}

void check_output_path(const std::string& path, OutputKind kind, const std::string& option) {
    namespace fs = std::filesystem;
    if (path.empty()) throw UsageError(option + " must not be empty");
    const fs::path p(path);
    std::error_code ec;
    if (fs::is_directory(p, ec)) throw UsageError(fmt::format("{} {}: is a folder, expected a file name", option, path));
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) throw UsageError(fmt::format("{} {}: folder {} does not exist", option, path, dir.string()));
    if (::access(dir.c_str(), W_OK) != 0) throw UsageError(fmt::format("{} {}: folder {} is not writable", option, path, dir.string()));
    std::string name = p.filename().string();
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    auto ends = [&](const std::string& e) { return name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0; };
    if (kind == OutputKind::kImage) {
        for (const char* e : {".nii.gz", ".nii", ".mha", ".mhd", ".nrrd", ".nhdr", ".mnc", ".mgz", ".mgh", ".mgh.gz"})
            if (ends(e)) return;
        throw UsageError(fmt::format("{} {}: unknown image format; use .nii.gz, .nii, .mha, .mhd, .nrrd, .nhdr, .mnc or .mgz", option, path));
    }
    if (kind == OutputKind::kMesh) {
        try {
            mesh_format_for_path(p);
        } catch (const std::exception&) {
            throw UsageError(fmt::format("{} {}: unknown mesh format; use .ply, .obj or .stl", option, path));
        }
    }
}

InterruptGuard::InterruptGuard() {
    if (g_guard_depth++ > 0) return;
    g_interrupted.store(false);
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

InterruptGuard::~InterruptGuard() {
    if (--g_guard_depth > 0) return;
    struct sigaction sa {};
    sa.sa_handler = SIG_DFL;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
}

const std::atomic<bool>& InterruptGuard::flag() const { return g_interrupted; }

ProgressLine::ProgressLine(bool quiet) : enabled_(!quiet && ::isatty(STDERR_FILENO) == 1) {}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(const std::string& text, bool force) {
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    if (!force && dirty_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    fmt::print(stderr, "\r\033[K{}", text);
    std::fflush(stderr);
    dirty_ = true;
}

void ProgressLine::finish() {
    if (enabled_ && dirty_) {
        fmt::print(stderr, "\n");
        dirty_ = false;
    }
}

}  // namespace liveset::cli
