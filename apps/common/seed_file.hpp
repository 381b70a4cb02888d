// Seed files: the seeds of a session as `liveset segment --seed` takes them, one I,J,K:R per line
// (0-based voxel indices, radius in voxels; '#' starts a comment, blank lines are skipped). The
// viewer saves and loads them; `--seed "$(sed -n 1p seeds.txt)"` feeds a line to the CLI.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "liveset/segment/intensity.hpp"

namespace liveset::cli {

// "I,J,K:R" with the shortest decimal that reads back to the same double (bit-exact round trip).
std::string format_seed(const SeedBall& seed);
// The file's text: a comment line, then one format_seed() per line.
std::string format_seed_file(const std::vector<SeedBall>& seeds);
// Parses a seed file's text (parse_seed_voxel per line, `default_radius` where a line has no :R);
// UsageError "<name> line N: ..." on a malformed line.
std::vector<SeedBall> parse_seed_file(const std::string& text, const std::string& name, double default_radius);
// Reads and parses `path` (UsageError when it cannot be read).
std::vector<SeedBall> read_seed_file(const std::filesystem::path& path, double default_radius);
// Writes the seeds atomically.
void write_seed_file(const std::filesystem::path& path, const std::vector<SeedBall>& seeds);

}  // namespace liveset::cli
