// `liveset demo --brain`: the real-brain demo on the bundled BrainWeb sample (cmd_demo_brain.cpp).
#pragma once

#include <string>

namespace liveset::cli {

struct BrainDemoArgs {
    std::string data = LIVESET_DATA_DIR "/brainweb";  // the bundled sample
    std::string out = "liveset-demo-brain";
    bool json = false, quiet = false;
    bool repair = false;  // --repair: the paper's Figure 5 (finder_repair.hpp)
};

int run_brain_demo(const BrainDemoArgs& args, int threads);

}  // namespace liveset::cli
