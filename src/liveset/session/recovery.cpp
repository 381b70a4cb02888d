// Recovery files: encoding, strict decoding, atomic writes (the crash-signal writer is the viewer's).
#include "liveset/session/recovery.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include "liveset/base/atomic_file.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset {

static_assert(std::endian::native == std::endian::little, "recovery files are written in the host's byte order (little-endian)");

namespace {

constexpr char kMagic[8] = {'L', 'S', 'R', 'E', 'C', 'O', 'V', '1'};
constexpr std::uint32_t kVersion = 6;  // 1: the flags byte held window_from_seeds only; 2: no smooth_mm; 3: no ROI; 4: no step; 5: no coarse start
constexpr std::uint32_t kMaxPath = 4096;
constexpr std::uint32_t kMaxSeeds = 100000;
// The coarse start's byte in the file is its index here.
constexpr std::array<CoarseStart, 3> kCoarseStarts{CoarseStart::kAuto, CoarseStart::kOn, CoarseStart::kOff};

template <class T>
void put(std::vector<std::uint8_t>& out, T value) {
    const std::size_t at = out.size();
    out.resize(at + sizeof(T));
    std::memcpy(out.data() + at, &value, sizeof(T));
}

}  // namespace

namespace recovery_format {

std::vector<std::uint8_t> encode_header(const std::string& image, const SessionMarks& marks, std::optional<std::uint64_t> roi_checksum,
                                        RecordedStep step, CoarseStart coarse_start, const Lattice& lattice) {
    if (image.size() > kMaxPath) throw std::runtime_error("recovery: the image path is too long");
    if (marks.seeds.size() > kMaxSeeds) throw std::runtime_error("recovery: too many seeds");
    std::vector<std::uint8_t> out;
    out.reserve(256 + image.size() + 32 * marks.seeds.size());
    for (char c : kMagic) out.push_back(static_cast<std::uint8_t>(c));
    put(out, kVersion);
    put(out, std::uint32_t{0});
    put(out, std::int64_t{0});
    put(out, static_cast<std::uint32_t>(image.size()));
    for (char c : image) out.push_back(static_cast<std::uint8_t>(c));
    const Vec3i d = lattice.dims();
    for (int v : {d.x, d.y, d.z}) put(out, static_cast<std::int32_t>(v));
    const Vec3d s = lattice.spacing(), o = lattice.origin();
    for (double v : {s.x, s.y, s.z, o.x, o.y, o.z}) put(out, v);
    for (double v : lattice.direction()) put(out, v);
    const ThresholdParams& p = marks.params;
    for (double v : {p.mu, p.epsilon, p.n, p.alpha, p.smooth_mm}) put(out, v);
    put(out, static_cast<std::uint8_t>((marks.window_from_seeds ? 1 : 0) | (marks.alpha_automatic ? 2 : 0)));
    put(out, static_cast<std::int32_t>(marks.iterations));
    put(out, static_cast<std::uint32_t>(marks.seeds.size()));
    for (const SeedBall& b : marks.seeds)
        for (double v : {b.center.x, b.center.y, b.center.z, b.radius}) put(out, v);
    put(out, static_cast<std::uint8_t>(roi_checksum ? 1 : 0));
    put(out, roi_checksum.value_or(0));
    put(out, static_cast<std::uint8_t>(step.sleeping ? 1 : 0));
    put(out, static_cast<std::uint8_t>(step.thin_fronts ? 1 : 0));
    put(out, static_cast<std::uint8_t>(std::ranges::find(kCoarseStarts, coarse_start) - kCoarseStarts.begin()));
    put(out, static_cast<std::uint64_t>(lattice.size()));
    return out;
}

}  // namespace recovery_format

namespace {

using recovery_format::Fnv;
using recovery_format::kFixedHead;
using recovery_format::kSignalOffset;
using recovery_format::kTimeOffset;

class Reader {
public:
    Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    template <class T>
    T get(const char* what) {
        need(sizeof(T), what);
        T v;
        std::memcpy(&v, data_ + pos_, sizeof(T));
        pos_ += sizeof(T);
        return v;
    }
    double finite(const char* what) {
        const double v = get<double>(what);
        if (!std::isfinite(v)) throw std::runtime_error(std::string("non-finite ") + what);
        return v;
    }
    const std::uint8_t* take(std::size_t n, const char* what) {
        need(n, what);
        const std::uint8_t* p = data_ + pos_;
        pos_ += n;
        return p;
    }
    std::size_t remaining() const { return size_ - pos_; }

private:
    void need(std::size_t n, const char* what) const {
        if (n > size_ - pos_) throw std::runtime_error(std::string("truncated (in the ") + what + ")");
    }
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t pos_ = 0;
};

}  // namespace

std::uint64_t mask_checksum(const Grid<std::uint8_t>& mask) {
    Fnv h;
    for (const std::uint8_t v : mask.values()) {
        const std::uint8_t inside = v != 0;
        h.add(&inside, 1);
    }
    return h.h;
}

std::string roi_difference(std::optional<std::uint64_t> saved, std::optional<std::uint64_t> now) {
    if (saved == now) return {};
    if (!saved) return "saved without a ROI, opened with one";
    if (!now) return "saved with a ROI, opened without one";
    return "saved with another ROI";
}

std::filesystem::path recovery_path(const std::filesystem::path& dir, const std::string& image, const std::string& variant) {
    std::error_code ec;
    std::filesystem::path full = std::filesystem::weakly_canonical(std::filesystem::absolute(image, ec), ec);
    if (ec) full = std::filesystem::path(image).lexically_normal();
    Fnv h;
    const std::string key = full.string();
    h.add(key.data(), key.size());
    std::string name = std::filesystem::path(image).filename().string();
    if (name.empty()) name = "image";
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.h));
    return dir / (name + "-" + hex + (variant.empty() ? "" : "-" + variant) + ".lsrecovery");
}

std::vector<std::uint8_t> encode_recovery(const RecoveryView& state) {
    if (state.status.size() != state.phi.size()) throw std::runtime_error("recovery: status and phi differ in size");
    std::vector<std::uint8_t> out = recovery_format::encode_header(state.image, state.marks, state.roi_checksum, state.step, state.coarse_start,
                                                                              state.phi.lattice());
    const auto sig = static_cast<std::uint32_t>(state.signal);
    std::memcpy(out.data() + kSignalOffset, &sig, sizeof sig);
    std::memcpy(out.data() + kTimeOffset, &state.unix_time, sizeof state.unix_time);
    const std::span<const float> phi = state.phi.values();
    const std::size_t at = out.size();
    out.resize(at + phi.size_bytes());
    std::memcpy(out.data() + at, phi.data(), phi.size_bytes());
    const std::span<const std::int8_t> status = state.status.values();
    const std::size_t at2 = out.size();
    out.resize(at2 + status.size());
    std::memcpy(out.data() + at2, status.data(), status.size());
    Fnv hash;
    hash.add(out.data(), out.size());
    put(out, hash.h);
    return out;
}

// Reads the format field by field in file order (the layout in recovery.hpp), so that it can be read
// side by side with that layout: a little over 80 lines on purpose.
RecoveryState decode_recovery(const std::uint8_t* data, std::size_t size) {
    Reader r(data, size);
    if (std::memcmp(r.take(8, "magic"), kMagic, 8) != 0) throw std::runtime_error("not a liveset recovery file (wrong magic)");
    if (size < 8 + sizeof(std::uint64_t)) throw std::runtime_error("truncated");
    Fnv hash;
    hash.add(data, size - sizeof(std::uint64_t));
    std::uint64_t stored;
    std::memcpy(&stored, data + size - sizeof stored, sizeof stored);
    const std::uint32_t version = r.get<std::uint32_t>("version");
    if (version < 1 || version > kVersion) throw std::runtime_error("unsupported recovery file version " + std::to_string(version));
    if (hash.h != stored) throw std::runtime_error("damaged (checksum mismatch)");

    RecoveryState s;
    const std::uint32_t sig = r.get<std::uint32_t>("signal");
    if (sig > 64) throw std::runtime_error("invalid signal number");
    s.signal = static_cast<int>(sig);
    s.unix_time = r.get<std::int64_t>("time");
    const std::uint32_t path_size = r.get<std::uint32_t>("image path");
    if (path_size > kMaxPath) throw std::runtime_error("image path too long");
    const std::uint8_t* path = r.take(path_size, "image path");
    s.image.assign(reinterpret_cast<const char*>(path), path_size);
    Vec3i dims;
    dims.x = r.get<std::int32_t>("dimensions");
    dims.y = r.get<std::int32_t>("dimensions");
    dims.z = r.get<std::int32_t>("dimensions");
    Vec3d spacing, origin;
    spacing.x = r.finite("spacing");
    spacing.y = r.finite("spacing");
    spacing.z = r.finite("spacing");
    origin.x = r.finite("origin");
    origin.y = r.finite("origin");
    origin.z = r.finite("origin");
    Mat3d direction;
    for (double& v : direction) v = r.finite("direction");
    Lattice lattice;
    try {
        lattice = Lattice(dims, spacing, origin, direction);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("invalid geometry: ") + e.what());
    }
    ThresholdParams& p = s.marks.params;
    p.mu = r.finite("parameters");
    p.epsilon = r.finite("parameters");
    p.n = r.finite("parameters");
    p.alpha = r.finite("parameters");
    if (version >= 3) p.smooth_mm = r.finite("parameters");  // older files: no smoothing, as they ran
    try {
        validate(p);
    } catch (const std::invalid_argument& e) {
        throw std::runtime_error(std::string("invalid parameters: ") + e.what());
    }
    const std::uint8_t flags = r.get<std::uint8_t>("parameters");
    if (flags > (version == 1 ? 1 : 3)) throw std::runtime_error("invalid flag");
    s.marks.window_from_seeds = (flags & 1) != 0;
    s.marks.alpha_automatic = (flags & 2) != 0;
    s.marks.pristine = false;
    s.marks.iterations = r.get<std::int32_t>("iterations");
    if (s.marks.iterations < 0) throw std::runtime_error("negative iteration count");
    const std::uint32_t seeds = r.get<std::uint32_t>("seed count");
    if (seeds > kMaxSeeds || seeds * 32ull > r.remaining()) throw std::runtime_error("invalid seed count");
    for (std::uint32_t i = 0; i < seeds; ++i) {
        SeedBall b;
        b.center.x = r.finite("seeds");
        b.center.y = r.finite("seeds");
        b.center.z = r.finite("seeds");
        b.radius = r.finite("seeds");
        if (b.radius <= 0) throw std::runtime_error("a seed with a non-positive radius");
        s.marks.seeds.push_back(b);
    }
    s.roi_recorded = version >= 4;
    if (s.roi_recorded) {
        const std::uint8_t has_roi = r.get<std::uint8_t>("ROI");
        if (has_roi > 1) throw std::runtime_error("invalid ROI flag");
        const std::uint64_t fnv = r.get<std::uint64_t>("ROI");
        if (has_roi) s.roi_checksum = fnv;
        else if (fnv != 0) throw std::runtime_error("a ROI checksum without a ROI");
    }
    if (version >= 5) {
        const std::uint8_t sleeping = r.get<std::uint8_t>("step");
        const std::uint8_t thin_fronts = r.get<std::uint8_t>("step");
        if (sleeping > 1 || thin_fronts > 1) throw std::runtime_error("invalid step");
        s.step = RecordedStep{sleeping == 1, thin_fronts == 1};
    }
    if (version >= 6) {
        const std::uint8_t coarse = r.get<std::uint8_t>("coarse start");
        if (coarse >= kCoarseStarts.size()) throw std::runtime_error("invalid coarse start");
        s.coarse_start = kCoarseStarts[coarse];
    }
    const std::uint64_t voxels = r.get<std::uint64_t>("voxel count");
    if (voxels != lattice.size()) throw std::runtime_error("the voxel count does not match the dimensions");
    const std::uint64_t payload = voxels * (sizeof(float) + 1) + sizeof(std::uint64_t);
    if (r.remaining() != payload) throw std::runtime_error(r.remaining() < payload ? "truncated (in phi)" : "trailing bytes after phi");
    const std::uint8_t* values = r.take(voxels * sizeof(float), "phi");
    s.phi = Grid<float>(lattice);
    std::memcpy(s.phi.values().data(), values, voxels * sizeof(float));
    for (float v : s.phi.values())
        if (!std::isfinite(v)) throw std::runtime_error("phi holds NaN or infinite values");
    const std::uint8_t* status = r.take(voxels, "status");
    s.status = Grid<std::int8_t>(lattice);
    std::memcpy(s.status.values().data(), status, voxels);
    // Statuses are not checked here: a crash in the middle of an update leaves transient values,
    // and Session::load_recovered falls back to φ's signs when the status is not a valid field.
    return s;
}

void write_recovery(const std::filesystem::path& path, const RecoveryView& state) {
    const std::vector<std::uint8_t> bytes = encode_recovery(state);
    try {
        write_file_atomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(path.string() + ": cannot write (" + e.what() + ")");
    }
}

RecoveryState read_recovery(const std::filesystem::path& path) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) throw std::runtime_error(path.string() + ": " + ec.message());
    if (size > kMaxLatticePoints * sizeof(float) + (std::uint64_t{1} << 24)) throw std::runtime_error(path.string() + ": too large for a recovery file");
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
    std::ifstream in(path, std::ios::binary);
    if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
        throw std::runtime_error(path.string() + ": cannot read");
    try {
        return decode_recovery(bytes.data(), bytes.size());
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(path.string() + ": " + e.what());
    }
}

}  // namespace liveset
