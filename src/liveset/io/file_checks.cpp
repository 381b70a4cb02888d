// Raw-byte checks of NIfTI and MetaImage files, and the orientation-code patch (see file_checks.hpp),
// with zlib's gz* functions, which read plain and gzip-compressed files alike.
#include "liveset/io/file_checks.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <vector>

namespace liveset::io_detail {

namespace {

namespace fs = std::filesystem;

template <class T>
T load(const unsigned char* p, bool swap) {
    std::array<unsigned char, sizeof(T)> b;
    std::memcpy(b.data(), p, sizeof(T));
    if (swap) std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
}

// Counts the non-finite values of `bytes` (and the NaN among them); flags the NaN in `nan_at`,
// grown only as far as the data read so far (`first` is the index of the chunk's first value), so
// a header promising more than the file holds allocates nothing for it.
template <class T>
void count_non_finite(const unsigned char* p, std::size_t bytes, bool swap, DataCheck& c, std::uint64_t first,
                      std::vector<std::uint8_t>* nan_at) {
    for (std::size_t i = 0; i + sizeof(T) <= bytes; i += sizeof(T)) {
        const T v = load<T>(p + i, swap);
        if (std::isfinite(v)) continue;
        ++c.non_finite;
        if (!std::isnan(v)) continue;
        ++c.nan;
        if (nan_at == nullptr) continue;
        const std::uint64_t at = first + i / sizeof(T);
        if (nan_at->size() <= at) nan_at->resize(static_cast<std::size_t>(first + bytes / sizeof(T)), 0);
        (*nan_at)[static_cast<std::size_t>(at)] = 1;
    }
}

std::string holds(std::uint64_t have, std::uint64_t need) {
    return "holds " + std::to_string(have) + " of " + std::to_string(need) + " data bytes";
}

struct GzClose {
    void operator()(gzFile_s* f) const { gzclose(f); }
};

// The gzip trailer's ISIZE: the uncompressed length modulo 2^32 (of the last member).
bool gzip_isize(const std::string& path, std::uint32_t& isize) {
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (!in || in.tellg() < 18) return false;
    in.seekg(-4, std::ios::end);
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    isize = std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
    return true;
}

std::string trim(const std::string& s) {
    const auto a = s.find_first_not_of(" \t\r");
    if (a == std::string::npos) return "";
    return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// Where a NIfTI's voxel data lies and what it holds, read from its header (the stream is left
// just after the header); nullopt when it is not one (ITK then has its say). `pair`: the header
// of a two-file image (.hdr + .img: NIfTI "ni1"/"ni2", or Analyze 7.5 with no magic), whose
// offset counts from the start of the .img.
struct NiftiLayout {
    bool swap = false;
    int datatype = 0;
    std::uint64_t offset = 0, data_bytes = 0;
    int header_bytes = 0;
};

std::optional<NiftiLayout> read_nifti_layout(gzFile f, bool pair) {
    // Read exactly the header (348 bytes for NIfTI-1, 540 for NIfTI-2): the data starts later.
    unsigned char h[540] = {};
    int got = gzread(f, h, 348);
    if (got < 348) return std::nullopt;  // ITK reads the header; nothing to add here
    // NIfTI-1 (348-byte header) or NIfTI-2 (540), either byte order; single file only.
    const auto size_le = load<std::int32_t>(h, false), size_be = load<std::int32_t>(h, true);
    const bool swap = !(size_le == 348 || size_le == 540);
    const std::int32_t sizeof_hdr = swap ? size_be : size_le;
    std::int64_t dim[8] = {};
    int datatype = 0, bitpix = 0;
    double vox_offset = 0;
    if (sizeof_hdr == 348) {
        // A pair's header: "ni1", or Analyze 7.5 (no magic; its vox_offset field is the same float).
        if (pair ? std::memcmp(h + 344, "n+1", 4) == 0 : std::memcmp(h + 344, "n+1", 4) != 0) return std::nullopt;
        for (int i = 0; i < 8; ++i) dim[i] = load<std::int16_t>(h + 40 + 2 * i, swap);
        datatype = load<std::int16_t>(h + 70, swap);
        bitpix = load<std::int16_t>(h + 72, swap);
        vox_offset = std::max<double>(pair ? 0 : 352, load<float>(h + 108, swap));
    } else if (sizeof_hdr == 540) {
        if (gzread(f, h + 348, 192) != 192) return std::nullopt;
        got = 540;
        if (std::memcmp(h + 4, pair ? "ni2" : "n+2", 4) != 0) return std::nullopt;
        for (int i = 0; i < 8; ++i) dim[i] = load<std::int64_t>(h + 16 + 8 * i, swap);
        datatype = load<std::int16_t>(h + 12, swap);
        bitpix = load<std::int16_t>(h + 14, swap);
        vox_offset = std::max<double>(pair ? 0 : 544, static_cast<double>(load<std::int64_t>(h + 168, swap)));
    } else {
        return std::nullopt;
    }
    if (dim[0] < 1 || dim[0] > 7 || bitpix <= 0 || bitpix % 8 != 0 || !(vox_offset < 1e15)) return std::nullopt;
    std::uint64_t data_bytes = static_cast<std::uint64_t>(bitpix / 8);
    for (int i = 1; i <= dim[0]; ++i) {
        if (dim[i] <= 0) return std::nullopt;
        data_bytes *= static_cast<std::uint64_t>(dim[i]);
    }
    return NiftiLayout{swap, datatype, static_cast<std::uint64_t>(vox_offset), data_bytes, pair ? 0 : got};
}

bool ends_with(const std::string& s, const char* suffix) {
    const std::size_t n = std::strlen(suffix);
    if (s.size() < n) return false;
    for (std::size_t i = 0; i < n; ++i)
        if (std::tolower(static_cast<unsigned char>(s[s.size() - n + i])) != suffix[i]) return false;
    return true;
}

// A two-file image's header and data files, named as niftilib finds them: x.hdr[.gz] with x.img,
// else x.img.gz (and the other way round), the partner's extension in the case of the one given
// (niftilib's nifti_findimgname: X.HDR with X.IMG); false for a single file.
bool pair_files(const std::string& path, std::string& header, std::string& data) {
    std::error_code ec;
    for (const char* ext : {".hdr.gz", ".hdr", ".img.gz", ".img"}) {
        if (!ends_with(path, ext)) continue;
        const std::size_t dot = path.size() - std::strlen(ext);
        const std::string stem = path.substr(0, dot);
        const bool is_header = ext[1] == 'h', upper = std::isupper(static_cast<unsigned char>(path[dot + 1])) != 0;
        std::string other = is_header ? ".img" : ".hdr", gz = ".gz";
        if (upper) {
            for (char& ch : other) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
            gz = ".GZ";
        }
        for (const std::string& candidate : {stem + other, stem + other + gz}) {
            if (!fs::exists(candidate, ec)) continue;
            header = is_header ? path : candidate;
            data = is_header ? candidate : path;
            return true;
        }
        return false;
    }
    return false;
}

}  // namespace

DataCheck check_nifti_data(const std::string& path, bool count_non_finite_values, std::vector<std::uint8_t>* nan_at) {
    DataCheck result;
    if (nan_at != nullptr) nan_at->clear();
    std::string header_path = path, data_path = path;
    const bool pair = pair_files(path, header_path, data_path);
    std::unique_ptr<gzFile_s, GzClose> file(gzopen(header_path.c_str(), "rb"));
    if (!file) return result;
    const std::optional<NiftiLayout> layout = read_nifti_layout(file.get(), pair);
    if (!layout) return result;
    if (pair) file.reset(gzopen(data_path.c_str(), "rb"));  // the data: from the .img's first byte
    if (!file) return result;
    gzFile f = file.get();
    const bool swap = layout->swap;
    const int datatype = layout->datatype;
    const std::uint64_t data_bytes = layout->data_bytes;
    const int got = layout->header_bytes;
    const std::uint64_t offset = layout->offset;
    const std::uint64_t end = offset + data_bytes;
    const bool is_float = datatype == 16 || datatype == 64;  // FLOAT32, FLOAT64
    const bool scan_values = count_non_finite_values && is_float;
    const bool compressed = gzdirect(f) == 0;

    // Cheap answers when no value needs looking at.
    if (!scan_values) {
        if (!compressed) {
            std::error_code ec;
            const std::uint64_t size = fs::file_size(data_path, ec);
            if (!ec && size < end) {
                result.truncated = true;
                result.detail = holds(size > offset ? size - offset : 0, data_bytes);
            }
            return result;
        }
        std::uint32_t isize = 0;
        if (gzip_isize(data_path, isize) && isize == static_cast<std::uint32_t>(end)) return result;
    }

    // Stream the data: count the bytes that are really there (and non-finite values).
    std::vector<unsigned char> buf(std::size_t{1} << 20);
    std::uint64_t pos = static_cast<std::uint64_t>(got);
    std::uint64_t have = 0;
    bool error = false;
    while (pos < offset) {  // skip to the data (header extensions)
        const auto want = static_cast<unsigned>(std::min<std::uint64_t>(buf.size(), offset - pos));
        const int n = gzread(f, buf.data(), want);
        if (n <= 0) {
            error = n < 0;
            break;
        }
        pos += static_cast<std::uint64_t>(n);
    }
    while (pos >= offset && have < data_bytes) {
        // Chunks are multiples of 8 bytes, so no value straddles two chunks (the data starts at
        // the first value; `have` stays a multiple of the value size).
        const auto want = static_cast<unsigned>(std::min<std::uint64_t>(buf.size(), data_bytes - have));
        const int n = gzread(f, buf.data(), want);
        if (n <= 0) {
            error = n < 0;
            break;
        }
        if (scan_values) {
            const std::uint64_t size = datatype == 16 ? 4 : 8;
            if (datatype == 16) count_non_finite<float>(buf.data(), std::size_t(n), swap, result, have / size, nan_at);
            else count_non_finite<double>(buf.data(), std::size_t(n), swap, result, have / size, nan_at);
        }
        have += static_cast<std::uint64_t>(n);
    }
    int errnum = Z_OK;
    gzerror(f, &errnum);
    if (have < data_bytes || error || (errnum != Z_OK && errnum != Z_STREAM_END)) {
        result.truncated = true;
        result.detail = holds(have, data_bytes);
        if (errnum != Z_OK && errnum != Z_STREAM_END) {
            const std::string why = gzerror(f, &errnum);  // "<path>: unexpected end of file"
            const auto colon = why.rfind(": ");
            result.detail += ", " + (colon == std::string::npos ? why : why.substr(colon + 2));
        }
    }
    return result;
}

bool nifti_float_data_complete(const std::string& path) {
    std::string header_path = path, data_path = path;
    const bool pair = pair_files(path, header_path, data_path);
    std::unique_ptr<gzFile_s, GzClose> file(gzopen(header_path.c_str(), "rb"));
    if (!file) return false;
    const std::optional<NiftiLayout> layout = read_nifti_layout(file.get(), pair);
    if (!layout || (layout->datatype != 16 && layout->datatype != 64)) return false;  // FLOAT32, FLOAT64
    if (pair) file.reset(gzopen(data_path.c_str(), "rb"));
    if (!file) return false;
    const std::uint64_t end = layout->offset + layout->data_bytes;
    if (gzdirect(file.get()) != 0) {
        std::error_code ec;
        const std::uint64_t size = fs::file_size(data_path, ec);
        return !ec && size >= end;
    }
    std::uint32_t isize = 0;
    return gzip_isize(data_path, isize) && isize == static_cast<std::uint32_t>(end);
}

DataCheck check_metaimage_data(const std::string& path, std::uint64_t raw_bytes) {
    DataCheck result;
    std::ifstream in(path, std::ios::binary);
    if (!in) return result;
    bool compressed = false;
    std::uint64_t compressed_size = 0;
    long long header_size = 0;
    std::string data_file;
    std::string line;
    for (int lines = 0; lines < 500 && std::getline(in, line); ++lines) {
        const auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
        try {
            if (key == "CompressedData") compressed = value == "True" || value == "true" || value == "1";
            if (key == "CompressedDataSize") compressed_size = std::stoull(value);
            if (key == "HeaderSize") header_size = std::stoll(value);
        } catch (const std::exception&) {
            return result;  // odd header: leave it to ITK
        }
        if (key == "ElementDataFile") {
            data_file = value;
            break;
        }
    }
    if (data_file.empty()) return result;
    fs::path data;
    std::uint64_t offset = 0;
    std::string upper = data_file;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    if (upper == "LOCAL") {
        data = path;
        const auto at = in.tellg();
        if (at < 0) return result;
        offset = static_cast<std::uint64_t>(at);
    } else {
        if (upper.rfind("LIST", 0) == 0 || data_file.find('%') != std::string::npos ||
            data_file.find(' ') != std::string::npos)
            return result;
        data = fs::path(data_file).is_absolute() ? fs::path(data_file) : fs::path(path).parent_path() / data_file;
    }
    std::error_code ec;
    const std::uint64_t size = fs::file_size(data, ec);
    if (ec) {
        result.truncated = true;
        result.detail = "data file " + data.filename().string() + " is missing";
        return result;
    }
    std::uint64_t need = compressed ? compressed_size : raw_bytes;
    if (compressed && compressed_size == 0) return result;  // size unknown: leave it to ITK
    if (!compressed && header_size > 0) offset += static_cast<std::uint64_t>(header_size);
    if (!compressed && header_size == -1) offset = size > raw_bytes ? size - raw_bytes : 0;  // data at the end
    const std::uint64_t have = size > offset ? size - offset : 0;
    if (have < need) {
        result.truncated = true;
        result.detail = holds(have, need);
    }
    return result;
}

bool clear_nifti_orientation(const std::string& path) {
    // The codes' offsets: NIfTI-1 qform_code, sform_code int16 at 252, 254; NIfTI-2 int32 at 344, 348.
    std::array<unsigned char, 540> h{};
    bool compressed = false;
    std::size_t at = 0, width = 0;
    {
        std::unique_ptr<gzFile_s, GzClose> in(gzopen(path.c_str(), "rb"));
        if (!in) return false;
        compressed = gzdirect(in.get()) == 0;
        if (gzread(in.get(), h.data(), 348) != 348) return false;
        const bool n1 = load<std::int32_t>(h.data(), false) == 348 || load<std::int32_t>(h.data(), true) == 348;
        const bool n2 = load<std::int32_t>(h.data(), false) == 540 || load<std::int32_t>(h.data(), true) == 540;
        if (n1 && (std::memcmp(h.data() + 344, "n+1", 4) == 0 || std::memcmp(h.data() + 344, "ni1", 4) == 0)) {
            at = 252, width = 4;
        } else if (n2 && std::memcmp(h.data() + 4, "n+2", 4) == 0) {
            at = 344, width = 8;
        } else {
            return false;
        }
    }
    const std::vector<unsigned char> zeros(width, 0);  // 0 in either byte order
    if (!compressed) {
        std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(at));
        f.write(reinterpret_cast<const char*>(zeros.data()), static_cast<std::streamsize>(width));
        return static_cast<bool>(f.flush());
    }
    // Compressed: streamed through a second temporary (no copy of the image in memory), renamed over.
    const std::string patched = path + ".orient";
    std::unique_ptr<gzFile_s, GzClose> in(gzopen(path.c_str(), "rb"));
    gzFile out = in ? gzopen(patched.c_str(), "wb") : nullptr;
    bool ok = out != nullptr;
    std::vector<unsigned char> buf(std::size_t{1} << 22);
    for (bool first = true; ok; first = false) {
        const int n = gzread(in.get(), buf.data(), static_cast<unsigned>(buf.size()));
        if (n < 0) ok = false;
        if (n <= 0) break;
        if (first) {
            if (static_cast<std::size_t>(n) < at + width) ok = false;
            else std::memset(buf.data() + at, 0, width);
        }
        ok = ok && gzwrite(out, buf.data(), static_cast<unsigned>(n)) == n;
    }
    if (out != nullptr && gzclose(out) != Z_OK) ok = false;
    std::error_code ec;
    if (ok) fs::rename(patched, path, ec);
    if (!ok || ec) fs::remove(patched, ec);
    return ok && !ec;
}

}  // namespace liveset::io_detail
