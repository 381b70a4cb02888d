// Seed files in the CLI's --seed format, read and written.
#include "seed_file.hpp"

#include <fmt/core.h>

#include <fstream>
#include <sstream>

#include "cli_common.hpp"
#include "cli_support.hpp"

namespace liveset::cli {

std::string format_seed(const SeedBall& seed) {
    return fmt::format("{},{},{}:{}", seed.center.x, seed.center.y, seed.center.z, seed.radius);
}

std::string format_seed_file(const std::vector<SeedBall>& seeds) {
    std::string text = "# liveset seeds: I,J,K:R per line (0-based voxels, radius in voxels), as `liveset segment --seed`\n";
    for (const SeedBall& s : seeds) text += format_seed(s) + "\n";
    return text;
}

std::vector<SeedBall> parse_seed_file(const std::string& text, const std::string& name, double default_radius) {
    std::vector<SeedBall> seeds;
    std::istringstream in(text);
    int number = 0;
    for (std::string line; std::getline(in, line);) {
        ++number;
        if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        const auto first = line.find_first_not_of(" \t\r"), last = line.find_last_not_of(" \t\r");
        if (first == std::string::npos) continue;
        line = line.substr(first, last - first + 1);
        try {
            seeds.push_back(parse_seed_voxel(line, default_radius));
        } catch (const UsageError& e) {
            throw UsageError(fmt::format("{} line {}: {}", name, number, e.what()));
        }
    }
    return seeds;
}

std::vector<SeedBall> read_seed_file(const std::filesystem::path& path, double default_radius) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UsageError(fmt::format("cannot read the seed file {}", path.string()));
    std::ostringstream text;
    text << in.rdbuf();
    return parse_seed_file(text.str(), path.string(), default_radius);
}

void write_seed_file(const std::filesystem::path& path, const std::vector<SeedBall>& seeds) {
    write_atomically(path.string(), format_seed_file(seeds));
}

}  // namespace liveset::cli
