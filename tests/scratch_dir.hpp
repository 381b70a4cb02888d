// Scratch folders for tests: <temp>/liveset_test_<pid>/<name>, the whole root removed when the process exits.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace liveset::testing {

namespace detail {

// The process's scratch root (<temp>/liveset_test_<pid>; temp honours TMPDIR). Made on first use, after
// clearing whatever a dead process with the same pid left; removed recursively at normal exit, only by the
// process that made it (a forked child that exits normally leaves it alone), and kept when LIVESET_KEEP is set.
class ScratchRoot {
public:
    ScratchRoot()
        : owner_(::getpid()), path_(std::filesystem::temp_directory_path() / ("liveset_test_" + std::to_string(owner_))) {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
        std::filesystem::create_directories(path_);
    }
    ~ScratchRoot() {
        if (::getpid() != owner_ || std::getenv("LIVESET_KEEP")) return;
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    ScratchRoot(const ScratchRoot&) = delete;
    ScratchRoot& operator=(const ScratchRoot&) = delete;

    const std::filesystem::path& path() const { return path_; }

private:
    pid_t owner_;
    std::filesystem::path path_;
};

inline const std::filesystem::path& scratch_root() {
    static const ScratchRoot root;
    return root.path();
}

}  // namespace detail

// A fresh, empty folder <temp>/liveset_test_<pid>/<name> (removed first if it exists). Names are per process:
// two callers in one test program must pick different names; `name` is a non-empty relative path without "..".
inline std::filesystem::path scratch_dir(const std::string& name) {
    const std::filesystem::path rel(name);
    bool escapes = name.empty() || !rel.is_relative();
    for (const auto& part : rel) escapes = escapes || part == "..";
    if (escapes) throw std::invalid_argument("scratch_dir: not a plain relative name: '" + name + "'");
    const std::filesystem::path d = detail::scratch_root() / rel;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

}  // namespace liveset::testing
