// Pieces of liveset_io's error messages (see messages.hpp).
#include "liveset/io/messages.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>

#include <cstring>
#include <filesystem>
#include <sstream>

namespace liveset::io_detail {

SilencedStderr::SilencedStderr() {
    std::fflush(stderr);
    saved_ = ::dup(2);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
    if (null >= 0) ::close(null);
}

SilencedStderr::~SilencedStderr() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
}


std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string dims_text(const std::vector<std::uint64_t>& size) {
    std::string s;
    for (std::size_t i = 0; i < size.size(); ++i) {
        if (i) s += 'x';
        s += std::to_string(size[i]);
    }
    return s;
}

std::string bytes_text(double bytes) {
    const char* units[] = {"bytes", "KiB", "MiB", "GiB", "TiB"};
    int u = 0;
    for (; u < 4 && bytes >= 1024; ++u) bytes /= 1024;
    std::ostringstream os;
    os.precision(u ? 3 : 12);
    os << bytes << ' ' << units[u];
    return os.str();
}

std::string voxels_are_non_finite(std::uint64_t n) {
    return std::to_string(n) + (n == 1 ? " voxel is" : " voxels are") + " NaN or infinite";
}

std::string voxels_are_infinite(std::uint64_t n) { return std::to_string(n) + (n == 1 ? " voxel is" : " voxels are") + " infinite"; }

std::string condense(const std::string& text, const std::string& path) {
    std::string s;
    s.reserve(text.size());
    for (char c : text) s += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
    for (const char* prefix : {"ITK ERROR: ", "itk::ERROR: "})
        for (std::size_t at; (at = s.find(prefix)) != std::string::npos;) {
            const std::size_t paren = s.find("(0x", at), end = s.find("): ", at);
            s.erase(at, (paren != std::string::npos && end != std::string::npos && paren < end)
                            ? end + 3 - at
                            : std::strlen(prefix));
        }
    if (const auto nrrd = s.rfind("[nrrd] "); nrrd != std::string::npos) {
        s = s.substr(nrrd + 7);
        const auto colon = s.find(": ");
        if (colon != std::string::npos && s.find(' ') > colon) s = s.substr(colon + 2);  // "_nrrdFunc: "
    }
    const std::string name = quoted(std::filesystem::path(path).filename().string());
    for (const std::string& p : {quoted(path), path})
        for (std::size_t at = 0; !path.empty() && (at = s.find(p, at)) != std::string::npos; at += name.size())
            s.replace(at, p.size(), name);
    std::string out;
    for (char c : s)
        if (!(c == ' ' && (out.empty() || out.back() == ' '))) out += c;
    while (!out.empty() && (out.back() == ' ' || out.back() == '.' || out.back() == ':')) out.pop_back();
    if (out.size() > 240) out = out.substr(0, 237) + "...";
    return out.empty() ? "unknown error" : out;
}

}  // namespace liveset::io_detail
