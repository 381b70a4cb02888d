// Shared pieces of the viewer's tests: the 48³ phantom and a seeded session on it, bit-for-bit φ
// comparison, JSON index triples, and whether a tool (xvfb-run, xdotool) is installed.
#pragma once

#include <bit>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "liveset/phantom/phantom.hpp"
#include "liveset/session/session.hpp"
#include "render_test_util.hpp"

namespace liveset::testing {

inline const Phantom& phantom48() { return phantom_of_size<48>(); }

// A session on the 48³ phantom with its seeds added (one undoable action).
inline std::unique_ptr<Session> seeded_session(const SessionOptions& options) {
    auto s = std::make_unique<Session>(phantom48().image, options);
    for (const Vec3i& c : phantom48().seeds) s->add_seed({c.cast<double>(), 2.0});
    s->end_action();
    return s;
}

inline bool same_bits(const Grid<float>& a, const Grid<float>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::bit_cast<std::uint32_t>(a[static_cast<PointIndex>(i)]) != std::bit_cast<std::uint32_t>(b[static_cast<PointIndex>(i)]))
            return false;
    return true;
}

inline Vec3i vec3i(const nlohmann::json& j) { return {j[0].get<int>(), j[1].get<int>(), j[2].get<int>()}; }

inline bool have(const char* tool) { return std::system((std::string("command -v ") + tool + " >/dev/null 2>&1").c_str()) == 0; }

}  // namespace liveset::testing
