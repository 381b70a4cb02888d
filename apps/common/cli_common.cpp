// CLI helpers: validators, thread control and atomic file output.
#include "cli_common.hpp"

#include "liveset/base/atomic_file.hpp"

#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>

namespace liveset::cli {

CLI::Validator finite_number() {
    return CLI::Validator(
        [](std::string& s) -> std::string {
            try {
                std::size_t used = 0;
                const double v = std::stod(s, &used);
                if (used != s.size()) return "not a number: " + s;
                if (!std::isfinite(v)) return "value must be finite, got " + s;
            } catch (const std::exception&) {
                return "not a number: " + s;
            }
            return {};
        },
        "FINITE");
}

std::shared_ptr<void> limit_threads(int threads) {
    if (threads <= 0) return nullptr;
    return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<std::size_t>(threads));
}

void write_atomically(const std::string& path, const std::string& text) {
    try {
        write_file_atomically(path, text);
    } catch (const std::runtime_error& e) {
        throw UsageError("cannot write " + path + ": " + e.what());
    }
}

}  // namespace liveset::cli
