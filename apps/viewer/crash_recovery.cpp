// The viewer's crash path (see crash_recovery.hpp): async-signal-safe calls only in the handler.
#include "crash_recovery.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <memory>
#include <stdexcept>

#include "liveset/base/atomic_file.hpp"

namespace liveset {

namespace {

using recovery_format::Fnv;
using recovery_format::kFixedHead;
using recovery_format::kSignalOffset;

// Static storage only, read by the signal handler.
struct TrackedState {
    std::unique_ptr<std::uint8_t[]> header;
    std::size_t header_size = 0;
    const float* phi = nullptr;
    const std::int8_t* status = nullptr;
    std::size_t voxels = 0;
};

constexpr std::array<int, 8> kSignals{SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTERM, SIGINT, SIGHUP};
std::array<TrackedState, 2> g_slots;
std::atomic<int> g_active{-1};
std::atomic<bool> g_installed{false};
std::atomic<bool> g_writing{false};
std::array<char, 4200> g_path{};
std::array<char, 4210> g_temp{};
std::array<struct sigaction, kSignals.size()> g_previous{};

bool write_fd(int fd, const void* data, std::size_t n, Fnv& hash) {
    hash.add(data, n);
    const auto* p = static_cast<const char*>(data);
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        p += w;
        n -= static_cast<std::size_t>(w);
    }
    return true;
}

void write_from_handler(int sig) {
    const int slot = g_active.load();
    if (slot < 0 || g_writing.exchange(true)) return;
    const TrackedState& s = g_slots[static_cast<std::size_t>(slot)];
    const int fd = ::open(g_temp.data(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (fd < 0) return;
    Fnv hash;
    const auto signal_number = static_cast<std::uint32_t>(sig);
    const auto now = static_cast<std::int64_t>(::time(nullptr));
    bool ok = write_fd(fd, s.header.get(), kSignalOffset, hash) && write_fd(fd, &signal_number, sizeof signal_number, hash) &&
              write_fd(fd, &now, sizeof now, hash) &&
              write_fd(fd, s.header.get() + kFixedHead, s.header_size - kFixedHead, hash) &&
              write_fd(fd, s.phi, s.voxels * sizeof(float), hash) && write_fd(fd, s.status, s.voxels, hash);
    const std::uint64_t sum = hash.h;
    Fnv ignored;
    ok = ok && write_fd(fd, &sum, sizeof sum, ignored) && ::fsync(fd) == 0;
    ::close(fd);
    if (!ok || rename_into_place(g_temp.data(), g_path.data()) != 0) ::unlink(g_temp.data());
}

extern "C" void liveset_recovery_signal(int sig) {
    write_from_handler(sig);
    discard_temporaries();  // an autosave (or a save) the signal interrupted leaves no temporary
    // SA_RESETHAND restored the default action: deliver the signal again to take it (a fault
    // re-raises itself when the handler returns).
    ::raise(sig);
}

}  // namespace

CrashRecovery::CrashRecovery(std::filesystem::path path) : path_(std::move(path)) {
    if (g_installed.exchange(true)) throw std::logic_error("CrashRecovery: one instance at a time");
    // Its own temporary name (an autosave may be writing its temporary when the signal comes).
    const std::string p = path_.string(), t = signal_temp_path(path_).string();
    if (t.size() >= g_temp.size()) {
        g_installed = false;
        throw std::runtime_error(p + ": path too long for a recovery file");
    }
    std::memcpy(g_path.data(), p.c_str(), p.size() + 1);
    std::memcpy(g_temp.data(), t.c_str(), t.size() + 1);
    struct sigaction action {};
    action.sa_handler = liveset_recovery_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &action, &g_previous[i]);
}

CrashRecovery::~CrashRecovery() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &g_previous[i], nullptr);
    g_active = -1;
    for (TrackedState& s : g_slots) s = {};
    g_installed = false;
}

void CrashRecovery::track(const std::string& image, const SessionMarks& marks, std::optional<std::uint64_t> roi_checksum,
                          RecordedStep step, CoarseStart coarse_start, const Grid<float>& phi, const Grid<std::int8_t>& status) {
    if (status.size() != phi.size()) throw std::invalid_argument("CrashRecovery::track: status and phi differ in size");
    const std::vector<std::uint8_t> header = recovery_format::encode_header(image, marks, roi_checksum, step, coarse_start, phi.lattice());
    const int slot = g_active.load() == 0 ? 1 : 0;
    TrackedState& s = g_slots[static_cast<std::size_t>(slot)];
    s.header = std::make_unique<std::uint8_t[]>(header.size());
    std::memcpy(s.header.get(), header.data(), header.size());
    s.header_size = header.size();
    s.phi = phi.values().data();
    s.status = status.values().data();
    s.voxels = phi.size();
    g_active = slot;
}

void CrashRecovery::untrack() { g_active = -1; }

}  // namespace liveset
