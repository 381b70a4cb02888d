// `liveset demo --brain`: the real-brain demo on the bundled BrainWeb sample (cmd_demo_brain.cpp).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/session/session.hpp"

namespace liveset::cli {

struct BrainDemoArgs {
    std::string data = LIVESET_DATA_DIR "/brainweb";  // the bundled sample
    std::string out = "liveset-demo-brain";
    bool json = false, quiet = false;
    bool repair = false;  // --repair: the paper's Figure 5 (cmd_demo_brain_repair.cpp)
};

int run_brain_demo(const BrainDemoArgs& args, int threads);

// What the repair half of `demo --brain --repair` needs from the segmentation half.
struct BrainRepairInput {
    const Grid<float>& t1;              // bias-corrected, raw units
    const Grid<std::uint8_t>& roi;      // brain mask
    IntensityScale scale;               // the segmentation's normalisation
    double band_lower = 0, band_upper = 0;  // the grey matter's band (tissue model, raw)
    double sheet_mean = 0;              // the grey matter's class mean (raw)
};

// Finder -> targets -> one 200-agent sheet-rule round per target, through `session` (which holds
// the segmentation) -> verdicts; returns the report's "repair" object (targets, verdicts, counts).
nlohmann::json repair_brain_holes(const BrainRepairInput& in, Session& session, bool quiet);
// The demo's sub-optimally low threshold: ε = this × the tissue model window's half width.
double brain_repair_epsilon_scale();
// ... but not below this many σ of the grey-matter class (98.4 % of its Gaussian inside the window).
double brain_repair_min_sigmas();

}  // namespace liveset::cli
