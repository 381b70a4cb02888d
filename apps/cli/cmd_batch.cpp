// `liveset batch MANIFEST.csv --out DIR [--workers N | --scheduler ADDRESS]`: cohort processing on
// Dask distributed, implemented in Python (python/liveset/batch.py). This command replaces itself
// with `python3 -m liveset.batch ARGS...`, the build's Python package first on PYTHONPATH.
#include <fmt/core.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "commands.hpp"

namespace liveset::cli {

namespace {

[[noreturn]] void exec_python_batch(const std::vector<std::string>& args) {
#if defined(LIVESET_PYTHON_EXECUTABLE) && defined(LIVESET_PYTHON_DIR)
    std::string path = LIVESET_PYTHON_DIR;
    if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += std::string(":") + old;
    ::setenv("PYTHONPATH", path.c_str(), 1);
    std::vector<std::string> argv{LIVESET_PYTHON_EXECUTABLE, "-m", "liveset.batch"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> c;
    for (std::string& s : argv) c.push_back(s.data());
    c.push_back(nullptr);
    std::fflush(stdout);
    ::execv(c[0], c.data());
    fmt::print(stderr, "liveset: error: cannot run {}: {}\n", LIVESET_PYTHON_EXECUTABLE, std::strerror(errno));
    std::exit(127);
#else
    (void)args;
    fmt::print(stderr, "liveset: error: batch needs the Python module (configure with -DLIVESET_BUILD_PYTHON=ON)\n");
    std::exit(1);
#endif
}

}  // namespace

void add_batch_command(CLI::App& app) {
    auto* batch = app.add_subcommand("batch", "process a cohort (MANIFEST.csv) on Dask: liveset batch MANIFEST.csv --out DIR [--workers N | --scheduler ADDRESS]; see liveset batch --help");
    batch->prefix_command();
    batch->set_help_flag();  // --help goes to the Python implementation
    batch->callback([batch] { exec_python_batch(batch->remaining()); });
}

}  // namespace liveset::cli
