// Internal to liveset_io: pieces of the one-line, user-facing error messages. No ITK in here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace liveset::io_detail {

std::string quoted(const std::string& s);                        // "\"s\""
std::string dims_text(const std::vector<std::uint64_t>& size);  // "181x217x180"
std::string bytes_text(double bytes);                            // "2.71 KiB"
std::string voxels_are_non_finite(std::uint64_t n);              // "3 voxels are NaN or infinite"
std::string voxels_are_infinite(std::uint64_t n);                // "3 voxels are infinite"

// One line out of a library's error text (ITK, teem, ...): drops "ITK ERROR: Class(0x..):"
// prefixes and line breaks, shortens `path` to its file name (the message names the full path
// already), keeps only the innermost cause of teem's "[nrrd] a: trouble [nrrd] b: ..." chains,
// and caps the length.
std::string condense(const std::string& text, const std::string& path);

// While alive, the process's stderr (file descriptor 2) goes to /dev/null: the C libraries under
// ITK (niftilib, teem, libminc) print their own diagnostics there ("** ERROR: NWAD: wrote only 0 of
// ... bytes") before ITK throws, and liveset reports each failure in one line of its own. Not for
// concurrent use from several threads (the descriptor is process-wide).
class SilencedStderr {
public:
    SilencedStderr();
    ~SilencedStderr();
    SilencedStderr(const SilencedStderr&) = delete;
    SilencedStderr& operator=(const SilencedStderr&) = delete;

private:
    int saved_ = -1;
};

}  // namespace liveset::io_detail
