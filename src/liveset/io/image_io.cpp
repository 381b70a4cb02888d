// Image reading through ITK (writing: image_write.cpp). ITK ImageIO objects are driven directly (no
// ImageFileReader templates per pixel type), the IO factories liveset supports are registered
// explicitly once (itk_io.hpp), and every ITK failure is turned into a one-line ImageIoError that
// names the file.
#include "liveset/io/image_io.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <new>
#include <sstream>
#include <type_traits>
#include <vector>

#include <tbb/task_group.h>

#include <itkGDCMImageIO.h>
#include <itkGDCMSeriesFileNames.h>
#include <itkImage.h>
#include <itkImageIOBase.h>
#include <itkImageIOFactory.h>
#include <itkImageSeriesReader.h>
#include <itkMetaDataObject.h>
#include <itkNiftiImageIO.h>

#include "liveset/base/atomic_file.hpp"
#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/io/file_checks.hpp"
#include "liveset/io/itk_io.hpp"
#include "liveset/io/messages.hpp"
#include "liveset/io/mgh_image_io.hpp"
#include "liveset/io/minc_world.hpp"

namespace liveset {

namespace {

namespace fs = std::filesystem;
using Component = itk::IOComponentEnum;
using io_detail::bytes_text;
using io_detail::check_data;
using io_detail::condense;
using io_detail::create_io;
using io_detail::dims_text;
using io_detail::fail_read;
using io_detail::flip_ras_lps;
using io_detail::is_minc;
using io_detail::prepare_io;
using io_detail::quoted;
using io_detail::register_factories;
using io_detail::voxels_are_infinite;
using io_detail::voxels_are_non_finite;

std::string format_name(const itk::ImageIOBase& io) {
    const std::string cls = io.GetNameOfClass();
    if (cls == "NiftiImageIO") return "NIfTI";
    if (cls == "MetaImageIO") return "MetaImage";
    if (cls == "NrrdImageIO") return "NRRD";
    if (cls == "MINCImageIO") return "MINC";
    if (cls == "GDCMImageIO") return "DICOM";
    if (cls == "MghImageIO") return "MGH";
    const auto at = cls.find("ImageIO");
    return at == std::string::npos ? cls : cls.substr(0, at);
}

const char* kFormatsHint =
    "liveset reads .nii/.nii.gz, .mha/.mhd, .nrrd/.nhdr, .mnc, .mgh/.mgz and folders of DICOM slices";

// False for a NIfTI (or Analyze) header whose qform and sform codes are both 0 (NIFTI_XFORM_UNKNOWN):
// its axes carry no orientation, ITK reads them as LPS identity.
bool orientation_known(const itk::ImageIOBase& io) {
    if (const auto* mgh = dynamic_cast<const io_detail::MghImageIO*>(&io)) return mgh->orientation_known();  // its goodRASflag
    if (std::string(io.GetNameOfClass()) != "NiftiImageIO") return true;
    std::string q, s;
    const itk::MetaDataDictionary& dict = io.GetMetaDataDictionary();
    if (!itk::ExposeMetaData<std::string>(dict, "qform_code", q) || !itk::ExposeMetaData<std::string>(dict, "sform_code", s)) return true;
    return !(q == "0" && s == "0");
}

// ---------------------------------------------------------------------------------------------
// Opening: header of a file or of a DICOM series folder

struct Source {
    std::string path;
    ImageHeader header;
    std::vector<std::uint64_t> size;        // every axis the file stores
    bool scalar = true;                     // pixel type SCALAR (or a 1-component equivalent)
    itk::ImageIOBase::Pointer io;           // set for files
    std::vector<std::string> dicom_files;   // set for DICOM series folders
};

// The DICOM series in a folder (file lists sorted by slice position), largest first.
std::vector<std::vector<std::string>> dicom_series(const std::string& dir) {
    auto names = itk::GDCMSeriesFileNames::New();
    names->SetUseSeriesDetails(true);  // keeps scouts / other orientations out of the volume
    // "No Series were found" is our answer to give, not a warning to print.
    const bool warnings = itk::Object::GetGlobalWarningDisplay();
    itk::Object::GlobalWarningDisplayOff();
    std::vector<std::string> uids;
    try {
        names->SetDirectory(dir);
        uids = names->GetSeriesUIDs();
    } catch (...) {
        itk::Object::SetGlobalWarningDisplay(warnings);
        throw;
    }
    itk::Object::SetGlobalWarningDisplay(warnings);
    std::vector<std::vector<std::string>> series;
    for (const auto& uid : uids) {
        auto files = names->GetFileNames(uid);
        if (!files.empty()) series.push_back(std::move(files));
    }
    std::stable_sort(series.begin(), series.end(),
                     [](const auto& a, const auto& b) { return a.size() > b.size(); });
    return series;
}

void fill_geometry(Source& src, unsigned n, const std::vector<double>& spacing, const std::vector<double>& origin,
                   const std::vector<std::vector<double>>& axes) {
    ImageHeader& h = src.header;
    h.dimension = static_cast<int>(n);
    for (unsigned a = 0; a < 3; ++a) {
        if (a >= n) continue;  // 2D: the third axis keeps size 1, identity direction
        if (src.size[a] > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
            fail_read(src.path, "is too large: the header claims " + dims_text(src.size) + " voxels");
        h.dims[static_cast<int>(a)] = static_cast<int>(src.size[a]);
        h.spacing[static_cast<int>(a)] = spacing[a];
        h.origin[static_cast<int>(a)] = origin[a];
        for (unsigned r = 0; r < 3; ++r)
            h.direction[r * 3 + a] = r < n && r < axes[a].size() ? axes[a][r] : (r == a ? 1.0 : 0.0);
    }
    for (unsigned a = n; a < 3; ++a) h.dims[static_cast<int>(a)] = 1;
}

void open_file(Source& src) {
    const std::string& path = src.path;
    if (::access(path.c_str(), R_OK) != 0)
        fail_read(path, std::string("cannot open it (") + std::strerror(errno) + ")");
    std::error_code ec;
    if (fs::file_size(path, ec) == 0 && !ec) fail_read(path, "file is empty (0 bytes)");
    itk::ImageIOBase::Pointer io;
    try {
        io = create_io(path, itk::IOFileModeEnum::ReadMode);
    } catch (const itk::ExceptionObject& e) {
        fail_read(path, "file is corrupt or truncated (" + condense(e, path) + ")");
    }
    if (!io && lowercase_extension(fs::path(path).filename().string()) == ".mnc.gz")  // as BrainWeb serves its MINC
        fail_read(path, "is a gzip-compressed MINC file, which ITK's MINC reader does not open: gunzip it first");
    if (!io) fail_read(path, std::string("unknown image format or damaged header (") + kFormatsHint + ")");
    try {
        prepare_io(*io);
        io->SetFileName(path);
        io->ReadImageInformation();
    } catch (const itk::ExceptionObject& e) {
        fail_read(path, "file is corrupt or truncated (" + condense(e, path) + ")");
    } catch (const std::invalid_argument& e) {  // a header we read and do not support (MGH)
        fail_read(path, e.what());
    } catch (const std::exception& e) {
        fail_read(path, std::string("file is corrupt or truncated (") + e.what() + ")");
    }
    const unsigned n = io->GetNumberOfDimensions();
    src.size.resize(n);
    std::vector<double> spacing(n), origin(n);
    std::vector<std::vector<double>> axes(n);
    for (unsigned a = 0; a < n; ++a) {
        src.size[a] = io->GetDimensions(a);
        spacing[a] = io->GetSpacing(a);
        origin[a] = io->GetOrigin(a);
        axes[a] = io->GetDirection(a);
    }
    if (is_minc(*io)) flip_ras_lps(origin, axes);  // MINC's RAS -> LPS
    fill_geometry(src, n, spacing, origin, axes);
    src.header.components = static_cast<int>(io->GetNumberOfComponents());
    src.scalar = io->GetPixelType() == itk::IOPixelEnum::SCALAR && io->GetNumberOfComponents() == 1;
    src.header.pixel_type = itk::ImageIOBase::GetComponentTypeAsString(io->GetComponentType());
    if (!src.scalar)
        src.header.pixel_type = itk::ImageIOBase::GetPixelTypeAsString(io->GetPixelType()) + " of " +
                                src.header.pixel_type;
    src.header.format = format_name(*io);
    src.header.orientation_known = orientation_known(*io);
    src.io = io;
}

using DicomImage = itk::Image<float, 3>;
using DicomReader = itk::ImageSeriesReader<DicomImage>;

DicomReader::Pointer dicom_reader(const std::vector<std::string>& files, itk::GDCMImageIO::Pointer& gdcm) {
    gdcm = itk::GDCMImageIO::New();
    auto reader = DicomReader::New();
    reader->SetImageIO(gdcm);
    reader->SetFileNames(files);
    return reader;
}

void open_dicom_dir(Source& src) {
    const std::string& path = src.path;
    if (::access(path.c_str(), R_OK | X_OK) != 0)
        fail_read(path, std::string("cannot open the folder (") + std::strerror(errno) + ")");
    std::vector<std::vector<std::string>> series;
    try {
        series = dicom_series(path);
    } catch (const itk::ExceptionObject& e) {
        fail_read(path, "cannot scan the folder for DICOM files (" + condense(e, path) + ")");
    }
    if (series.empty())
        fail_read(path, "is a folder with no DICOM series (give an image file, or a folder of DICOM slices)");
    src.dicom_files = series.front();
    itk::GDCMImageIO::Pointer gdcm;
    auto reader = dicom_reader(src.dicom_files, gdcm);
    try {
        reader->UpdateOutputInformation();
    } catch (const itk::ExceptionObject& e) {
        fail_read(path, "DICOM series is corrupt (" + condense(e, path) + ")");
    }
    const DicomImage* image = reader->GetOutput();
    const auto region = image->GetLargestPossibleRegion();
    src.size.resize(3);
    std::vector<double> spacing(3), origin(3);
    std::vector<std::vector<double>> axes(3, std::vector<double>(3));
    for (unsigned a = 0; a < 3; ++a) {
        src.size[a] = region.GetSize(a);
        spacing[a] = image->GetSpacing()[a];
        origin[a] = image->GetOrigin()[a];
        for (unsigned r = 0; r < 3; ++r) axes[a][r] = image->GetDirection()[r][a];
    }
    fill_geometry(src, 3, spacing, origin, axes);
    src.header.components = static_cast<int>(gdcm->GetNumberOfComponents());
    src.scalar = gdcm->GetNumberOfComponents() == 1;
    src.header.pixel_type = itk::ImageIOBase::GetComponentTypeAsString(gdcm->GetComponentType());
    if (!src.scalar)
        src.header.pixel_type = itk::ImageIOBase::GetPixelTypeAsString(gdcm->GetPixelType()) + " of " +
                                src.header.pixel_type;
    src.header.format = "DICOM series";
    if (series.size() > 1)
        src.header.format += " (largest of " + std::to_string(series.size()) + " in the folder)";
}

Source open_source(const std::string& path) {
    if (path.empty()) throw ImageIoError("cannot read an image: the path is empty");
    register_factories();
    Source src;
    src.path = path;
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (!fs::exists(status)) fail_read(path, "no such file or folder");
    if (fs::is_directory(status))
        open_dicom_dir(src);
    else
        open_file(src);
    return src;
}

// Refuses images liveset cannot hold as a 3D scalar Lattice; everything from the header only.
Lattice validate(const Source& src, std::uint64_t max_bytes) {
    const std::string& path = src.path;
    const ImageHeader& h = src.header;
    const std::string dims = dims_text(src.size);
    if (std::any_of(src.size.begin(), src.size.end(), [](std::uint64_t s) { return s == 0; }))
        fail_read(path, "image is empty (size " + dims + ")");
    const std::string slice_hint =
        h.format == "DICOM" ? " (for a DICOM series, give the folder that holds all its slices)" : "";
    if (src.size.size() < 3) fail_read(path, "is a 2D image (" + dims + "); liveset needs a 3D volume" + slice_hint);
    for (std::size_t a = 3; a < src.size.size(); ++a)
        if (src.size[a] > 1)
            fail_read(path, "is a " + std::to_string(src.size.size()) + "D image (" + dims +
                                "); liveset reads 3D volumes only (extract one volume first)");
    if (!src.scalar || h.components != 1)
        fail_read(path, "has " + std::to_string(h.components) + " components per voxel (" + h.pixel_type +
                            "); liveset needs a scalar (grey-level) image");
    double points = 1;
    for (std::size_t a = 0; a < 3; ++a) points *= static_cast<double>(src.size[a]);
    if (points > static_cast<double>(kMaxLatticePoints))
        fail_read(path, "image is too large: the header claims " + dims + " voxels, more than liveset's limit of " +
                            std::to_string(kMaxLatticePoints));
    if (points * sizeof(float) > static_cast<double>(max_bytes))
        fail_read(path, "image is too large: the header claims " + dims + " voxels (" +
                            bytes_text(points * sizeof(float)) + " as float), more than the memory limit of " +
                            bytes_text(static_cast<double>(max_bytes)));
    if (h.dims.x == 1 || h.dims.y == 1 || h.dims.z == 1)
        fail_read(path, "is a 2D image (a single slice, " + dims + "); liveset needs a 3D volume" + slice_hint);
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(h.spacing[a]) || h.spacing[a] <= 0) {
            std::ostringstream os;
            os << "has invalid spacing " << h.spacing.x << " x " << h.spacing.y << " x " << h.spacing.z
               << " (spacing must be positive and finite)";
            fail_read(path, os.str());
        }
    if (!all_finite(h.origin)) fail_read(path, "has a non-finite origin");
    try {
        return Lattice(h.dims, h.spacing, h.origin, h.direction);
    } catch (const std::invalid_argument&) {
        fail_read(path, "has a singular or non-finite direction matrix");
    }
}

// ---------------------------------------------------------------------------------------------
// Pixels

template <class F>
void dispatch(Component c, const std::string& path, F&& f) {
    switch (c) {
        case Component::UCHAR: return f(std::type_identity<unsigned char>{});
        case Component::CHAR: return f(std::type_identity<signed char>{});
        case Component::USHORT: return f(std::type_identity<unsigned short>{});
        case Component::SHORT: return f(std::type_identity<short>{});
        case Component::UINT: return f(std::type_identity<unsigned int>{});
        case Component::INT: return f(std::type_identity<int>{});
        case Component::ULONG: return f(std::type_identity<unsigned long>{});
        case Component::LONG: return f(std::type_identity<long>{});
        case Component::ULONGLONG: return f(std::type_identity<unsigned long long>{});
        case Component::LONGLONG: return f(std::type_identity<long long>{});
        case Component::FLOAT: return f(std::type_identity<float>{});
        case Component::DOUBLE: return f(std::type_identity<double>{});
        default:
            fail_read(path, "unsupported pixel type " + itk::ImageIOBase::GetComponentTypeAsString(c));
    }
}

// Reads the whole file into `buffer` (which holds size() values of the file's component type).
void read_file_pixels(const Source& src, void* buffer) {
    itk::ImageIORegion region(static_cast<unsigned>(src.size.size()));
    for (unsigned a = 0; a < src.size.size(); ++a) {
        region.SetIndex(a, 0);
        region.SetSize(a, src.size[a]);
    }
    try {
        src.io->SetIORegion(region);
        src.io->Read(buffer);
    } catch (const itk::ExceptionObject& e) {
        fail_read(src.path, "file is corrupt or truncated (" + condense(e, src.path) + ")");
    } catch (const std::bad_alloc&) {
        fail_read(src.path, "not enough memory to read the image");
    } catch (const std::exception& e) {
        fail_read(src.path, std::string("file is corrupt or truncated (") + e.what() + ")");
    }
}

// Calls sink(const T* values, count) with all voxels, T the stored type (float for DICOM).
template <class Sink>
void with_pixels(const Source& src, std::size_t count, Sink&& sink) {
    if (!src.dicom_files.empty()) {
        itk::GDCMImageIO::Pointer gdcm;
        auto reader = dicom_reader(src.dicom_files, gdcm);
        try {
            reader->Update();
        } catch (const itk::ExceptionObject& e) {
            fail_read(src.path, "DICOM series is corrupt or truncated (" + condense(e, src.path) + ")");
        } catch (const std::bad_alloc&) {
            fail_read(src.path, "not enough memory to read the image");
        }
        const DicomImage* image = reader->GetOutput();
        if (image->GetBufferedRegion().GetNumberOfPixels() != count)
            fail_read(src.path, "DICOM series changed while it was read");
        sink(image->GetBufferPointer(), count);
        return;
    }
    dispatch(src.io->GetComponentType(), src.path, [&](auto tag) {
        using T = typename decltype(tag)::type;
        LargeVector<T> buffer;  // huge pages: a brain's voxels fault in 2 MiB at a time
        try {
            buffer.resize(count);
        } catch (const std::bad_alloc&) {
            fail_read(src.path, "not enough memory to read the image");
        }
        read_file_pixels(src, buffer.data());
        sink(static_cast<const T*>(buffer.data()), count);
    });
}

void check_finite(const std::string& path, std::span<const float> values) {
    std::uint64_t bad = 0;
    for (float v : values) bad += !std::isfinite(v);
    if (bad) fail_read(path, voxels_are_non_finite(bad));
}

// The data check's verdict (see check_unless_beside).
void judge_data(const Source& src, const io_detail::DataCheck& check, const std::vector<std::uint8_t>* nan_at) {
    if (check.truncated) fail_read(src.path, "file is corrupt or truncated (" + check.detail + ")");
    if (nan_at == nullptr && check.non_finite) fail_read(src.path, voxels_are_non_finite(check.non_finite));
    if (const std::uint64_t inf = check.non_finite - check.nan; inf) fail_read(src.path, voxels_are_infinite(inf));
}

// The file's data check (io_detail::check_data: damage ITK's readers hide, NaN and infinite
// values), before anything is allocated — unless it would stream a NIfTI's float data once more
// and the file's size or gzip trailer says that data is all there: then it runs beside ITK's read,
// on another thread (read_with_check: a .nii.gz decompressed twice at once, 0.4 s less on a
// 0.7 mm head), and this returns true. So ITK never meets a short file. `nan_at`
// (NanVoxels::keep): receives where a NIfTI's NaN values lie (niftilib reads them as 0).
bool check_unless_beside(const Source& src, std::vector<std::uint8_t>* nan_at) {
    if (!src.io) return false;
    if (io_detail::data_check_may_overlap(*src.io, src.path)) return true;
    judge_data(src, io_detail::check_data(*src.io, src.path, true, nan_at), nan_at);
    return false;
}

// Reads the file's voxels through `read()`; with `beside` (check_unless_beside), the data check
// runs meanwhile on another thread (on one thread: in wait(), after the read), and a damaged file
// gets the check's one line before any error of the read.
template <class Read>
void read_with_check(const Source& src, std::vector<std::uint8_t>* nan_at, bool beside, Read&& read) {
    if (!beside) {
        read();
        return;
    }
    io_detail::DataCheck check;
    std::exception_ptr check_failed, read_failed;
    tbb::task_group both;
    both.run([&] {
        try {
            check = io_detail::check_data(*src.io, src.path, true, nan_at);
        } catch (...) {
            check_failed = std::current_exception();
        }
    });
    try {
        read();
    } catch (...) {
        read_failed = std::current_exception();
    }
    both.wait();
    if (check_failed) std::rethrow_exception(check_failed);
    judge_data(src, check, nan_at);
    if (read_failed) std::rethrow_exception(read_failed);
}

// NanVoxels::keep: NaN where the file holds it (`nan_at`, a NIfTI's, or NaN the reader kept);
// infinite values are still refused.
void keep_nan(const std::string& path, std::span<float> values, const std::vector<std::uint8_t>& nan_at) {
    const std::size_t flagged = std::min(nan_at.size(), values.size());
    for (std::size_t i = 0; i < flagged; ++i)
        if (nan_at[i]) values[i] = std::numeric_limits<float>::quiet_NaN();
    std::uint64_t inf = 0;
    for (float v : values) inf += std::isinf(v);
    if (inf) fail_read(path, voxels_are_infinite(inf));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Public API

ImageHeader read_image_header(const std::string& path) { return open_source(path).header; }

Grid<float> read_image(const std::string& path, std::uint64_t max_bytes, ImageHeader* header, NanVoxels nan) {
    const Source src = open_source(path);
    if (header != nullptr) *header = src.header;
    const Lattice lattice = validate(src, max_bytes);
    std::vector<std::uint8_t> nan_at;
    std::vector<std::uint8_t>* const nan_out = nan == NanVoxels::keep ? &nan_at : nullptr;
    const bool beside = check_unless_beside(src, nan_out);
    Grid<float> grid;
    try {
        grid = Grid<float>(lattice);
    } catch (const std::bad_alloc&) {
        fail_read(path, "not enough memory for " + dims_text(src.size) + " voxels");
    }
    std::span<float> out = grid.values();
    read_with_check(src, nan_out, beside, [&] {
        if (src.io && src.io->GetComponentType() == Component::FLOAT) {
            read_file_pixels(src, out.data());  // no conversion: straight into the grid
        } else {
            with_pixels(src, out.size(), [&](const auto* values, std::size_t n) {
                std::transform(values, values + n, out.begin(), [](auto v) { return static_cast<float>(v); });
            });
        }
    });
    if (nan == NanVoxels::keep) keep_nan(path, out, nan_at);
    else check_finite(path, out);
    return grid;
}

Grid<std::uint8_t> read_label_image(const std::string& path, std::uint64_t max_bytes, ImageHeader* header) {
    const Source src = open_source(path);
    if (header != nullptr) *header = src.header;
    const Lattice lattice = validate(src, max_bytes);
    const bool beside = check_unless_beside(src, nullptr);
    Grid<std::uint8_t> grid;
    try {
        grid = Grid<std::uint8_t>(lattice);
    } catch (const std::bad_alloc&) {
        fail_read(path, "not enough memory for " + dims_text(src.size) + " voxels");
    }
    std::span<std::uint8_t> out = grid.values();
    read_with_check(src, nullptr, beside, [&] {
        with_pixels(src, out.size(), [&](const auto* values, std::size_t n) {
            using T = std::remove_cv_t<std::remove_pointer_t<decltype(values)>>;
            std::size_t non_finite = 0, bad = 0, first_bad = n;
            for (std::size_t i = 0; i < n; ++i) {
                const T v = values[i];
                bool ok;
                if constexpr (std::is_floating_point_v<T>) {
                    if (!std::isfinite(v)) {
                        ++non_finite;
                        continue;
                    }
                    ok = v >= 0 && v <= 255 && v == std::floor(v);
                } else if constexpr (std::is_signed_v<T>) {
                    ok = v >= 0 && v <= 255;
                } else {
                    ok = v <= 255;
                }
                if (!ok) {
                    if (!bad++) first_bad = i;
                    continue;
                }
                out[i] = static_cast<std::uint8_t>(v);
            }
            if (non_finite) fail_read(path, voxels_are_non_finite(non_finite));
            if (bad) {
                std::ostringstream os;
                os.precision(9);
                os << "is not a label image: " << bad << (bad == 1 ? " voxel is" : " voxels are")
                   << " not an integer in 0..255 (e.g. " << +values[first_bad] << " at voxel "
                   << lattice.coord(static_cast<PointIndex>(first_bad)) << ")";
                fail_read(path, os.str());
            }
        });
    });
    return grid;
}

bool is_dicom_series_dir(const std::string& path) {
    std::error_code ec;
    if (path.empty() || !fs::is_directory(path, ec)) return false;
    register_factories();
    try {
        return !dicom_series(path).empty();
    } catch (...) {
        return false;
    }
}

}  // namespace liveset
