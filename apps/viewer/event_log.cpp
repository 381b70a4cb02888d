// Event log: JSON lines, rewritten atomically.
#include "event_log.hpp"

#include <fmt/core.h>

#include "cli_common.hpp"

namespace liveset::viewer {

void EventLog::add(const std::string& type, nlohmann::json fields) {
    if (!enabled()) return;
    nlohmann::json line = {{"frame", frame_}, {"type", type}};
    for (auto it = fields.begin(); it != fields.end(); ++it) line[it.key()] = it.value();
    text_ += line.dump() + "\n";
    try {
        cli::write_atomically(path_, text_);
    } catch (const std::exception& e) {
        fmt::print(stderr, "liveset: warning: event log switched off: {}\n", e.what());
        path_.clear();
    }
}

}  // namespace liveset::viewer
