// The viewer's event log (`--log-events FILE`): one JSON object per line for every user-visible
// action (camera gestures when they end, clicks, targets, seeds, buttons, keys, saves, exit), each
// with the frame number. The file is rewritten atomically at every event, so a reader (a test
// driving the window with xdotool) always sees complete lines - also while the viewer runs.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace liveset::viewer {

class EventLog {
public:
    EventLog() = default;
    explicit EventLog(std::string path) : path_(std::move(path)) {}

    bool enabled() const { return !path_.empty(); }
    void set_frame(std::uint64_t frame) { frame_ = frame; }
    // Adds {"frame": n, "type": type, ...fields} and rewrites the file (no-op when disabled).
    // A failing write is reported once on stderr and the log is switched off (never a crash).
    void add(const std::string& type, nlohmann::json fields = nlohmann::json::object());

private:
    std::string path_;
    std::uint64_t frame_ = 0;
    std::string text_;
};

}  // namespace liveset::viewer
