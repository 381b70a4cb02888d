// Sparse-field invariant checker and volume measures.
#include "liveset/levelset/invariants.hpp"
#include "liveset/levelset/layer_value.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace liveset {

namespace {

class Collector {
public:
    explicit Collector(InvariantReport& r) : report_(r) {}
    void add(const Lattice& lat, PointIndex i, const std::string& what) {
        ++report_.problem_count;
        if (report_.problems.size() >= 20) return;
        const Vec3i c = lat.coord(i);
        std::ostringstream os;
        os << "(" << c.x << "," << c.y << "," << c.z << "): " << what;
        report_.problems.push_back(os.str());
    }

private:
    InvariantReport& report_;
};

}  // namespace

std::string InvariantReport::summary() const {
    std::ostringstream os;
    os << problem_count << " invariant violation(s)";
    for (const auto& p : problems) os << "\n  " << p;
    return os.str();
}

InvariantReport check_invariants(const SparseField& field) {
    InvariantReport report;
    Collector bad(report);
    const Lattice& lat = field.lattice();
    const auto& phi = field.phi();
    const auto& status = field.status();
    const int n = field.layers();

    // Lists vs status: each listed point has the list's status, appears once; counts agree.
    std::vector<std::uint8_t> seen(lat.size(), 0);
    std::size_t listed = 0;
    for (int k = -n; k <= n; ++k)
        for (PointIndex i : field.layer(k)) {
            ++listed;
            if (i >= lat.size()) {
                ++report.problem_count;
                report.problems.push_back("layer list holds an index outside the lattice");
                continue;
            }
            if (seen[i]++) bad.add(lat, i, "listed more than once");
            if (status[i] != k) bad.add(lat, i, "in list " + std::to_string(k) + " with status " + std::to_string(status[i]));
        }
    std::size_t band = 0;
    for (std::size_t s = 0; s < lat.size(); ++s) {
        const auto i = static_cast<PointIndex>(s);
        const int st = status[i];
        const float v = phi[i];
        if (!std::isfinite(v)) bad.add(lat, i, "phi is not finite");
        if (st >= -n && st <= n) {
            ++band;
            if (!seen[i]) bad.add(lat, i, "band point missing from its layer list");
            if (v < st - 0.5f || v > st + 0.5f)
                bad.add(lat, i, "phi " + std::to_string(v) + " outside the range of layer " + std::to_string(st));
        } else if (st == n + 1 || st == -(n + 1)) {
            if (v != static_cast<float>(st)) bad.add(lat, i, "far value not clamped: " + std::to_string(v));
        } else {
            bad.add(lat, i, "invalid status " + std::to_string(st));
            continue;
        }
        // Neighbourhood structure.
        const Vec3i c = lat.coord(i);
        bool has_inner = false;
        const int inner = st > 0 ? st - 1 : st + 1;
        for (int a = 0; a < 3; ++a)
            for (int dir : {-1, 1}) {
                Vec3i q = c;
                q[a] += dir;
                if (!lat.contains(q)) continue;
                const int sq = status(q);
                // Layers are nested shells: neighbours differ by at most one layer, so inside and
                // outside never touch except through the zero layer.
                if (std::abs(sq - st) > 1)
                    bad.add(lat, i, "neighbour status " + std::to_string(sq) + " next to " + std::to_string(st));
                if (st != 0 && sq == inner) has_inner = true;
            }
        if (st != 0 && std::abs(st) <= n) {
            if (!has_inner) {
                bad.add(lat, i, "layer " + std::to_string(st) + " point has no neighbour in the next-inner layer");
            } else {
                const auto is_inner = [&](std::int8_t s) { return s == inner; };
                const float expect = detail::layer_value(phi, status, i, phi.lattice().coord(i), st > 0, is_inner);
                if (expect != v)
                    bad.add(lat, i, "outer-layer value " + std::to_string(v) + " differs from " + std::to_string(expect));
            }
        }
    }
    if (band != listed) {
        ++report.problem_count;
        report.problems.push_back("band has " + std::to_string(band) + " points but the lists hold " + std::to_string(listed));
    }
    return report;
}

double enclosed_volume(const SparseField& field) {
    // Fixed chunks summed in order: the same result whatever the thread count.
    const auto values = field.phi().values();
    constexpr std::size_t kChunk = 1 << 16;
    std::vector<double> partial((values.size() + kChunk - 1) / kChunk, 0.0);
    tbb::parallel_for(std::size_t{0}, partial.size(), [&](std::size_t c) {
        double local = 0.0;
        const std::size_t end = std::min(values.size(), (c + 1) * kChunk);
        for (std::size_t i = c * kChunk; i < end; ++i) local += std::clamp(0.5 - static_cast<double>(values[i]), 0.0, 1.0);
        partial[c] = local;
    });
    double sum = 0.0;
    for (double v : partial) sum += v;
    return sum;
}

double equivalent_radius(const SparseField& field) {
    return std::cbrt(3.0 * enclosed_volume(field) / (4.0 * std::numbers::pi));
}

}  // namespace liveset
