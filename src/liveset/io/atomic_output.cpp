// Atomic output through a hidden temporary (see atomic_output.hpp): write, fsync, rename(2).
#include "liveset/io/atomic_output.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>
#include <vector>

namespace liveset::io_detail {

namespace fs = std::filesystem;

namespace {

// Files in `dir` named `stem` + "." + anything: a temporary and its companions.
std::vector<fs::path> files_with_stem(const fs::path& dir, const std::string& stem) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.size() > stem.size() && name.compare(0, stem.size(), stem) == 0 && name[stem.size()] == '.')
            out.push_back(it->path());
    }
    return out;
}

// Replaces every occurrence of `from` by `to` in a small text file.
void replace_in_file(const fs::path& file, const std::string& from, const std::string& to) {
    std::string text;
    {
        std::ifstream in(file, std::ios::binary);
        std::ostringstream ss;
        ss << in.rdbuf();
        if (!in) throw std::runtime_error("cannot read back the header to fix its data file name");
        text = ss.str();
    }
    for (std::size_t at = 0; (at = text.find(from, at)) != std::string::npos; at += to.size())
        text.replace(at, from.size(), to);
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) throw std::runtime_error("cannot rewrite the header's data file name");
}

void sync_file(const fs::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY);
    const bool ok = fd >= 0 && ::fsync(fd) == 0;
    const int err = errno;
    if (fd >= 0) ::close(fd);
    if (!ok) throw std::runtime_error(std::string("cannot flush the file to disk (") + std::strerror(err) + ")");
}

}  // namespace

std::string extension_of(const std::string& filename) {
    const auto last = filename.rfind('.');
    if (last == std::string::npos || last == 0) return "";
    std::string tail = filename.substr(last);
    for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (tail == ".gz" && last > 0) {
        const auto prev = filename.rfind('.', last - 1);
        if (prev != std::string::npos && prev != 0) return filename.substr(prev);
    }
    return filename.substr(last);
}

AtomicOutput::AtomicOutput(const fs::path& target) : target_(target) {
    static std::atomic<unsigned> counter{0};
    dir_ = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const std::string name = target.filename().string();
    const std::string ext = extension_of(name);
    stem_ = name.substr(0, name.size() - ext.size());
    temp_stem_ = "." + stem_ + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    temp_ = dir_ / (temp_stem_ + ext);
}

AtomicOutput::~AtomicOutput() {
    if (committed_) return;
    std::error_code ec;
    for (const auto& f : files_with_stem(dir_, temp_stem_)) fs::remove(f, ec);
}

void AtomicOutput::create() {
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0)
        throw std::runtime_error("cannot create a file in folder \"" + dir_.string() + "\" (" + std::strerror(errno) +
                                 ")");
    ::close(fd);
}

void AtomicOutput::commit(bool text_header) {
    std::error_code ec;
    if (!fs::is_regular_file(temp_, ec)) throw std::runtime_error("the writer produced no file");
    std::vector<std::pair<fs::path, fs::path>> moves;  // companions first, the file itself last
    for (const auto& f : files_with_stem(dir_, temp_stem_))
        if (f != temp_) moves.emplace_back(f, dir_ / (stem_ + f.filename().string().substr(temp_stem_.size())));
    if (!moves.empty() && text_header) replace_in_file(temp_, temp_stem_, stem_);
    moves.emplace_back(temp_, target_);
    for (const auto& move : moves) sync_file(move.first);
    for (const auto& [from, to] : moves) {
        fs::rename(from, to, ec);
        if (ec) throw std::runtime_error("cannot rename the temporary file into place (" + ec.message() + ")");
    }
    committed_ = true;
    // The renames themselves reach the disk with the folder.
    const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

}  // namespace liveset::io_detail
