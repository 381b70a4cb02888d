// The one atomic file writer (see atomic_file.hpp): write a temporary, fsync, rename(2).
#include "liveset/base/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace liveset {

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
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    const bool ok = fd >= 0 && ::fsync(fd) == 0;
    const int err = errno;
    if (fd >= 0) ::close(fd);
    if (!ok) throw std::runtime_error(std::string("cannot flush the file to disk (") + std::strerror(err) + ")");
}

// The registry read by discard_temporaries(): fixed storage, claimed and released with atomics, so
// a signal handler can walk it at any moment.
constexpr int kSlots = 16;
constexpr std::size_t kPathBytes = 4096;
std::array<std::array<char, kPathBytes>, kSlots> g_temp_paths{};
std::array<std::atomic<int>, kSlots> g_slot_state{};  // 0 free, 1 being filled, 2 registered

int register_temporary(const fs::path& temp) {
    const std::string& text = temp.native();
    if (text.size() >= kPathBytes) return -1;
    for (int k = 0; k < kSlots; ++k) {
        int expected = 0;
        if (!g_slot_state[k].compare_exchange_strong(expected, 1)) continue;
        std::memcpy(g_temp_paths[k].data(), text.c_str(), text.size() + 1);
        g_slot_state[k].store(2);
        return k;
    }
    return -1;  // more than kSlots writes at once: this one is not covered
}

void release_temporary(int slot) {
    if (slot >= 0) g_slot_state[slot].store(0);
}

std::string reason_for_stream_error(int err) {
    if (err == ENOSPC || err == EDQUOT) return "write error: no space left on the device (disk full?)";
    return "write error (disk full?)";
}

}  // namespace

std::string file_extension(const std::string& filename) {
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

std::string lowercase_extension(const std::string& filename) {
    std::string e = file_extension(filename);
    for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

AtomicFile::AtomicFile(const fs::path& target) : target_(target) {
    static std::atomic<unsigned> counter{0};
    dir_ = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const std::string name = target.filename().string();
    const std::string ext = file_extension(name);
    stem_ = name.substr(0, name.size() - ext.size());
    temp_stem_ = "." + stem_ + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    temp_ = dir_ / (temp_stem_ + ext);
    slot_ = register_temporary(temp_);
}

AtomicFile::~AtomicFile() {
    release_temporary(slot_);
    if (committed_) return;
    std::error_code ec;
    for (const auto& f : files_with_stem(dir_, temp_stem_)) fs::remove(f, ec);
}

void AtomicFile::create() {
    const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0)
        throw std::runtime_error("cannot create a file in folder \"" + dir_.string() + "\" (" + std::strerror(errno) +
                                 ")");
    ::close(fd);
}

void AtomicFile::commit(bool text_header) {
    std::error_code ec;
    if (!fs::is_regular_file(temp_, ec)) throw std::runtime_error("the writer produced no file");
    std::vector<std::pair<fs::path, fs::path>> moves;  // companions first, the file itself last
    for (const auto& f : files_with_stem(dir_, temp_stem_))
        if (f != temp_) moves.emplace_back(f, dir_ / (stem_ + f.filename().string().substr(temp_stem_.size())));
    if (!moves.empty() && text_header) replace_in_file(temp_, temp_stem_, stem_);
    moves.emplace_back(temp_, target_);
    for (const auto& move : moves) sync_file(move.first);
    for (const auto& [from, to] : moves)
        if (const int err = rename_into_place(from.c_str(), to.c_str()); err != 0)
            throw std::runtime_error(std::string("cannot rename the temporary file into place (") + std::strerror(err) +
                                     ")");
    committed_ = true;
    release_temporary(slot_);
    slot_ = -1;
    // The renames themselves reach the disk with the folder.
    const int fd = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

void write_file_atomically(const fs::path& target, const std::function<void(std::ostream&)>& write) {
    AtomicFile file(target);
    file.create();
    {
        std::ofstream os(file.temp_path(), std::ios::binary | std::ios::trunc);
        if (!os) throw std::runtime_error(std::string("cannot open the temporary file (") + std::strerror(errno) + ")");
        write(os);
        errno = 0;
        os.flush();
        if (!os) throw std::runtime_error(reason_for_stream_error(errno));
        os.close();
        if (os.fail()) throw std::runtime_error(reason_for_stream_error(errno));
    }
    file.commit();
}

void write_file_atomically(const fs::path& target, std::string_view bytes) {
    write_file_atomically(target, [&](std::ostream& os) { os.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

void discard_temporaries() noexcept {
    for (int k = 0; k < kSlots; ++k)
        if (g_slot_state[k].load() == 2) ::unlink(g_temp_paths[k].data());
}

fs::path signal_temp_path(const fs::path& target) {
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    const std::string name = target.filename().string();
    const std::string ext = file_extension(name);
    std::string temp(".");  // appended piece by piece: gcc 12's -Wrestrict misfires on a + chain here
    temp.append(name, 0, name.size() - ext.size()).append(".crash-").append(std::to_string(::getpid())).append(ext);
    return dir / temp;
}

int rename_into_place(const char* temp, const char* target) noexcept {
    return std::rename(temp, target) == 0 ? 0 : errno;
}

}  // namespace liveset
