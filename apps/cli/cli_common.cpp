// CLI helpers: validators, thread control and atomic file output.
#include "cli_common.hpp"

#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <fstream>

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
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path tmp = target.parent_path() / (target.filename().string() + ".tmp");
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw UsageError("cannot write " + path);
        out << text;
        out.flush();
        if (!out) {
            out.close();
            fs::remove(tmp);
            throw UsageError("failed writing " + path);
        }
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw UsageError("cannot write " + path + ": " + ec.message());
    }
}

}  // namespace liveset::cli
