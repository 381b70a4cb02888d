// The wall time of a command's consecutive phases: `segment`'s "phase_seconds" report and time
// line, Python's `segment` report (docs/BENCHMARKS.md, session 85).
#pragma once

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace liveset::cli {

class PhaseTimes {
public:
    // Ends the phase in progress (begun at construction or at the last mark) under `phase`.
    void mark(const char* phase) {
        const auto now = Clock::now();
        phases_.emplace_back(phase, std::chrono::duration<double>(now - last_).count());
        last_ = now;
    }
    // {phase: seconds, ..., "total": their sum, from construction to the last mark}.
    nlohmann::json json() const {
        nlohmann::json j = nlohmann::json::object();
        for (const auto& [name, s] : phases_) j[name] = s;
        j["total"] = std::chrono::duration<double>(last_ - start_).count();
        return j;
    }
    // "read 1.6 s, roi 6.3 s, ... (35.0 s in all)", in the phases' order.
    std::string line() const {
        std::string s;
        for (auto [name, t] : phases_) {
            std::replace(name.begin(), name.end(), '_', ' ');
            s += fmt::format("{}{} {:.1f} s", s.empty() ? "" : ", ", name, t);
        }
        return s + fmt::format(" ({:.1f} s in all)", std::chrono::duration<double>(last_ - start_).count());
    }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point start_ = Clock::now(), last_ = start_;
    std::vector<std::pair<std::string, double>> phases_;
};

}  // namespace liveset::cli
