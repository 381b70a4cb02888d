// Plays a Script against a Viewer a little at a time: advance() performs at most one level-set or
// swarm step (or one other action), so a window keeps drawing while a script runs and the surface
// updates live; headless runs call it until done(). Failures throw cli::UsageError naming the
// entry ("script s.json entry 5 (\"click\"): no surface under pixel (10, 10)").
#pragma once

#include "script.hpp"

namespace liveset::viewer {

class ScriptPlayer {
public:
    explicit ScriptPlayer(Script script) : script_(std::move(script)) {}

    bool done() const { return next_ >= script_.actions.size(); }
    std::size_t position() const { return next_; }
    const Script& script() const { return script_; }
    void advance(Viewer& viewer);

private:
    [[noreturn]] void fail(const ScriptAction& a, const std::string& why) const;
    // fail() with the viewer's message unless `ok`.
    void check(Viewer& viewer, const ScriptAction& a, bool ok) const;
    void finish_entry(Viewer& viewer);
    void apply_params(Viewer& viewer, const ScriptAction& a);
    void move_camera(Viewer& viewer, const ScriptAction& a);
    void take_screenshot(Viewer& viewer, const ScriptAction& a);
    void report_perforations(Viewer& viewer, const ScriptAction& a);
    void report_eval(Viewer& viewer, const ScriptAction& a);

    Script script_;
    std::size_t next_ = 0;
    int steps_done_ = 0;  // within a multi-step entry
};

}  // namespace liveset::viewer
