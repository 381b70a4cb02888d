// The threshold parameters `liveset view` starts with, and one line saying where they came from:
// a workspace's, the tissue model's window for a level set loaded alone (the class most of its
// inside voxels fall in), the seeds' class, and the command line's --mu/--epsilon/--mu-raw/
// --epsilon-raw/--n/--alpha over any of them. Never silently the hard-coded defaults.
#pragma once

#include <string>

#include "liveset/session/session.hpp"
#include "threshold_args.hpp"

namespace liveset::viewer {

struct StartParams {
    const cli::ThresholdArgs* args = nullptr;  // the command line's values
    bool n_given = false, alpha_given = false;  // --n / --alpha given explicitly
    bool level_set_loaded = false;              // --phi or --mask
    std::string workspace;                      // the workspace applied (empty: none)
};

// Sets the session's parameters (Session::set_params; the undo history is then cleared, so the
// set-up cannot be undone into the defaults it replaced) and returns where they came
// from ("" when nothing was chosen: no level set, no seeds, nothing given). Throws cli::UsageError
// on values the speed refuses (as `liveset segment` does).
std::string choose_start_params(Session& session, const StartParams& start);

}  // namespace liveset::viewer
