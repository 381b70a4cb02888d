// FreeSurfer MGH/MGZ reading and writing (see mgh_image_io.hpp), with zlib's gz* functions, which
// read plain and gzip-compressed files alike.
#include "liveset/io/mgh_image_io.hpp"
#include "liveset/base/atomic_file.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

namespace liveset::io_detail {

namespace {

constexpr std::size_t kHeaderBytes = 284;
constexpr int kUchar = 0, kInt = 1, kFloat = 3, kShort = 4;

struct GzClose {
    void operator()(gzFile_s* f) const { gzclose(f); }
};
using Gz = std::unique_ptr<gzFile_s, GzClose>;

// ".mgh", ".mgz" or ".mgh.gz" (any case) when `path` ends so, else "".
std::string mgh_extension(const std::string& path) {
    const std::string e = lowercase_extension(std::filesystem::path(path).filename().string());
    return e == ".mgh" || e == ".mgz" || e == ".mgh.gz" ? e : std::string();
}

// Big-endian values in a byte buffer, and back.
template <class T>
T load_be(const unsigned char* p) {
    std::array<unsigned char, sizeof(T)> b;
    std::memcpy(b.data(), p, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
}

template <class T>
void store_be(unsigned char* p, T v) {
    std::array<unsigned char, sizeof(T)> b;
    std::memcpy(b.data(), &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) std::reverse(b.begin(), b.end());
    std::memcpy(p, b.data(), sizeof(T));
}

// Reverses each `size`-byte value in place (big-endian file <-> little-endian memory).
void swap_values(unsigned char* p, std::size_t bytes, std::size_t size) {
    if (size == 1 || std::endian::native == std::endian::big) return;
    for (std::size_t i = 0; i + size <= bytes; i += size) std::reverse(p + i, p + i + size);
}

std::size_t type_size(int type) { return type == kUchar ? 1 : type == kShort ? 2 : 4; }

// Reads exactly `bytes` (gzread takes at most INT_MAX at a time); false when the file is shorter.
bool read_exact(gzFile f, unsigned char* p, std::size_t bytes) {
    while (bytes > 0) {
        const unsigned want = static_cast<unsigned>(std::min<std::size_t>(bytes, std::size_t{1} << 30));
        const int n = gzread(f, p, want);
        if (n <= 0) return false;
        p += n;
        bytes -= static_cast<std::size_t>(n);
    }
    return true;
}

}  // namespace

bool is_mgh_name(const std::string& path) { return !mgh_extension(path).empty(); }

MghImageIO::MghImageIO() {
    AddSupportedReadExtension(".mgh");
    AddSupportedReadExtension(".mgz");
    AddSupportedReadExtension(".mgh.gz");
    AddSupportedWriteExtension(".mgh");
    AddSupportedWriteExtension(".mgz");
    AddSupportedWriteExtension(".mgh.gz");
    SetNumberOfComponents(1);
    SetPixelType(itk::IOPixelEnum::SCALAR);
    SetByteOrderToBigEndian();
}

bool MghImageIO::CanReadFile(const char* path) {
    if (!is_mgh_name(path)) return false;
    Gz f(gzopen(path, "rb"));
    unsigned char h[4];
    return f && read_exact(f.get(), h, 4) && load_be<std::int32_t>(h) == 1;
}

bool MghImageIO::CanWriteFile(const char* path) { return is_mgh_name(path); }

void MghImageIO::ReadImageInformation() {
    Gz f(gzopen(GetFileName(), "rb"));
    if (!f) throw std::runtime_error("cannot open the file");
    std::array<unsigned char, kHeaderBytes> h{};
    if (!read_exact(f.get(), h.data(), 90)) throw std::runtime_error("the MGH header is short");
    if (load_be<std::int32_t>(h.data()) != 1)
        throw std::invalid_argument("is not an MGH file (its version is " + std::to_string(load_be<std::int32_t>(h.data())) + ", not 1)");
    std::int32_t dims[4];
    for (int i = 0; i < 4; ++i) dims[i] = load_be<std::int32_t>(h.data() + 4 + 4 * i);
    type_ = load_be<std::int32_t>(h.data() + 20);
    if (type_ != kUchar && type_ != kInt && type_ != kFloat && type_ != kShort)
        throw std::invalid_argument("has MGH voxel type " + std::to_string(type_) + ", which liveset does not read (uchar, int, float or short)");
    for (int i = 0; i < 4; ++i)
        if (dims[i] <= 0) throw std::runtime_error("the MGH header gives a non-positive size");
    orientation_known_ = load_be<std::int16_t>(h.data() + 28) > 0;
    double spacing[3] = {1, 1, 1}, mdc[3][3] = {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}}, centre[3] = {0, 0, 0};  // nibabel's default
    if (orientation_known_) {
        for (int i = 0; i < 3; ++i) spacing[i] = load_be<float>(h.data() + 30 + 4 * i);
        for (int a = 0; a < 3; ++a)
            for (int r = 0; r < 3; ++r) mdc[a][r] = load_be<float>(h.data() + 42 + 12 * a + 4 * r);  // axis a's RAS cosines
        for (int i = 0; i < 3; ++i) centre[i] = load_be<float>(h.data() + 78 + 4 * i);
    }
    SetNumberOfDimensions(dims[3] > 1 ? 4 : 3);
    // The RAS of voxel 0: the centre voxel (dims / 2) lies at `centre`. LPS: R and A negated.
    double origin[3] = {centre[0], centre[1], centre[2]};
    for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) origin[r] -= mdc[a][r] * spacing[a] * dims[a] / 2.0;
    for (unsigned a = 0; a < 3; ++a) {
        SetDimensions(a, static_cast<itk::SizeValueType>(dims[a]));
        SetSpacing(a, spacing[a]);
        SetOrigin(a, a < 2 ? -origin[a] : origin[a]);
        SetDirection(a, std::vector<double>{-mdc[a][0], -mdc[a][1], mdc[a][2]});
    }
    if (dims[3] > 1) {
        SetDimensions(3, static_cast<itk::SizeValueType>(dims[3]));
        SetSpacing(3, 1.0);
        SetOrigin(3, 0.0);
    }
    SetComponentType(type_ == kUchar ? itk::IOComponentEnum::UCHAR
                     : type_ == kInt ? itk::IOComponentEnum::INT
                     : type_ == kShort ? itk::IOComponentEnum::SHORT
                                       : itk::IOComponentEnum::FLOAT);
}

void MghImageIO::Read(void* buffer) {
    std::size_t count = 1;
    for (unsigned a = 0; a < GetNumberOfDimensions(); ++a) count *= GetDimensions(a);
    const std::size_t bytes = count * type_size(type_);
    Gz f(gzopen(GetFileName(), "rb"));
    if (!f) throw std::runtime_error("cannot open the file");
    auto* out = static_cast<unsigned char*>(buffer);
    std::array<unsigned char, kHeaderBytes> header;
    if (!read_exact(f.get(), header.data(), kHeaderBytes) || !read_exact(f.get(), out, bytes))
        throw std::runtime_error("the file holds fewer than the header's " + std::to_string(bytes) + " data bytes");
    swap_values(out, bytes, type_size(type_));
}

void MghImageIO::Write(const void* buffer) {
    if (GetNumberOfDimensions() != 3) throw std::runtime_error("MGH files are written in 3D");
    const itk::IOComponentEnum c = GetComponentType();
    if (c != itk::IOComponentEnum::UCHAR && c != itk::IOComponentEnum::FLOAT)
        throw std::runtime_error("MGH files are written as uchar or float");
    const int type = c == itk::IOComponentEnum::UCHAR ? kUchar : kFloat;
    std::array<unsigned char, kHeaderBytes> h{};
    store_be<std::int32_t>(h.data(), 1);
    std::size_t count = 1;
    double mdc[3][3], spacing[3], centre[3];
    for (unsigned a = 0; a < 3; ++a) {
        const auto n = GetDimensions(a);
        count *= n;
        store_be<std::int32_t>(h.data() + 4 + 4 * a, static_cast<std::int32_t>(n));
        spacing[a] = GetSpacing(a);
        const std::vector<double> d = GetDirection(a);  // LPS
        mdc[a][0] = -d[0], mdc[a][1] = -d[1], mdc[a][2] = d[2];
    }
    for (int r = 0; r < 3; ++r) {
        centre[r] = r < 2 ? -GetOrigin(static_cast<unsigned>(r)) : GetOrigin(static_cast<unsigned>(r));
        for (unsigned a = 0; a < 3; ++a) centre[r] += mdc[a][r] * spacing[a] * static_cast<double>(GetDimensions(a)) / 2.0;
    }
    store_be<std::int32_t>(h.data() + 16, 1);  // frames
    store_be<std::int32_t>(h.data() + 20, type);
    store_be<std::int16_t>(h.data() + 28, 1);  // goodRASflag
    for (int i = 0; i < 3; ++i) store_be<float>(h.data() + 30 + 4 * i, static_cast<float>(spacing[i]));
    for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) store_be<float>(h.data() + 42 + 12 * a + 4 * r, static_cast<float>(mdc[a][r]));
    for (int i = 0; i < 3; ++i) store_be<float>(h.data() + 78 + 4 * i, static_cast<float>(centre[i]));

    const std::size_t size = type_size(type), bytes = count * size;
    const auto* data = static_cast<const unsigned char*>(buffer);
    const bool compress = mgh_extension(GetFileName()) != ".mgh";  // .mgz, .mgh.gz
    gzFile f = gzopen(GetFileName(), compress ? "wb6" : "wbT");  // T: plain, no gzip wrapper
    if (f == nullptr) throw std::runtime_error("cannot create the file");
    bool ok = gzwrite(f, h.data(), kHeaderBytes) == static_cast<int>(kHeaderBytes);
    std::vector<unsigned char> chunk(std::size_t{1} << 20);  // big-endian a chunk at a time (a whole-buffer copy doubled the memory)
    for (std::size_t at = 0; ok && at < bytes;) {
        const std::size_t n = std::min(bytes - at, chunk.size());
        std::memcpy(chunk.data(), data + at, n);
        swap_values(chunk.data(), n, size);
        ok = gzwrite(f, chunk.data(), static_cast<unsigned>(n)) == static_cast<int>(n);
        at += n;
    }
    const std::array<unsigned char, 20> footer{};  // TR, flip angle, TE, TI, FoV: unknown
    ok = ok && gzwrite(f, footer.data(), footer.size()) == static_cast<int>(footer.size());
    if (gzclose(f) != Z_OK || !ok) throw std::runtime_error("the file could not be written whole (disk full?)");
}

}  // namespace liveset::io_detail
