// Image writing through ITK (image_io.hpp): the format by the file name, geometry (MINC in RAS),
// written to a temporary, read back and checked, then renamed over the target.
#include "liveset/io/image_io.hpp"

#include <filesystem>
#include <string>
#include <vector>

#include "liveset/base/atomic_file.hpp"
#include "liveset/io/itk_io.hpp"
#include "liveset/io/messages.hpp"
#include "liveset/io/minc_world.hpp"

namespace liveset {

namespace {

namespace fs = std::filesystem;
using Component = itk::IOComponentEnum;
using namespace io_detail;  // itk_io.hpp, messages.hpp, minc_world.hpp

// Hands the lattice's geometry to a writer (MINC: converted to RAS) and sets the whole image as the region.
void set_geometry(itk::ImageIOBase& io, const Lattice& lattice) {
    io.SetNumberOfDimensions(3);
    const Vec3i d = lattice.dims();
    const Vec3d s = lattice.spacing(), o = lattice.origin();
    const Mat3d& m = lattice.direction();
    std::vector<double> origin{o.x, o.y, o.z};
    std::vector<std::vector<double>> axes;
    for (unsigned a = 0; a < 3; ++a) axes.push_back({m[a], m[3 + a], m[6 + a]});
    if (is_minc(io)) {
        prepare_io(io);
        flip_ras_lps(origin, axes);  // LPS -> MINC's RAS
    }
    itk::ImageIORegion region(3);
    for (unsigned a = 0; a < 3; ++a) {
        const int ai = static_cast<int>(a);
        io.SetDimensions(a, static_cast<itk::SizeValueType>(d[ai]));
        io.SetSpacing(a, s[ai]);
        io.SetOrigin(a, origin[a]);
        io.SetDirection(a, axes[a]);
        region.SetIndex(a, 0);
        region.SetSize(a, static_cast<itk::SizeValueType>(d[ai]));
    }
    io.SetIORegion(region);
}

void write_grid(const void* data, Component component, const Lattice& lattice, const std::string& path, const WriteOptions& options) {
    if (path.empty()) throw ImageIoError("cannot write an image: the path is empty");
    if (lattice.size() == 0) fail_write(path, "the image is empty");
    const fs::path target(path);
    const std::string filename = target.filename().string();
    const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    const auto dir_status = fs::status(dir, ec);
    if (!fs::exists(dir_status)) fail_write(path, "folder " + quoted(dir.string()) + " does not exist");
    if (!fs::is_directory(dir_status)) fail_write(path, quoted(dir.string()) + " is not a folder");
    if (filename.empty() || fs::is_directory(target, ec)) fail_write(path, "is a folder, not a file name");
    const std::string ext = file_extension(filename);
    const char* formats = "use .nii.gz, .nii, .mha, .mhd, .nrrd, .nhdr, .mnc or .mgz";
    if (ext.empty()) fail_write(path, std::string("no file extension to choose the format (") + formats + ")");

    register_factories();
    itk::ImageIOBase::Pointer io;
    try {
        io = create_io(path, itk::IOFileModeEnum::WriteMode);
    } catch (const itk::ExceptionObject&) {
        io = nullptr;
    }
    if (!io) fail_write(path, "unknown image format " + quoted(ext) + " for writing (" + formats + ")");
    const std::string cls = io->GetNameOfClass();
    if (cls == "GDCMImageIO") fail_write(path, std::string("writing DICOM is not supported (") + formats + ")");

    set_geometry(*io, lattice);
    const Vec3i d = lattice.dims();
    io->SetPixelType(itk::IOPixelEnum::SCALAR);
    io->SetComponentType(component);
    io->SetNumberOfComponents(1);
    // Two-file formats stay uncompressed (.raw, readable by anything); single files are compressed
    // where the format allows it (.nii vs .nii.gz is decided by the extension itself).
    const bool two_file = cls == "MetaImageIO" ? ext != ".mha" : (cls == "NrrdImageIO" && ext != ".nrrd");
    io->SetUseCompression(!two_file);

    // Uncompressed output must fit, known before writing. Checked up front because some writers
    // do not clean up after a failed write: teem keeps a detached .raw open (its disk space stays
    // used), libminc leaks its HDF5 file (HDF5 may then crash at exit). MINC is checked against
    // the uncompressed size.
    const std::string ext_lc = lowercase_extension(filename);
    const double bytes = double(lattice.size()) * (component == Component::FLOAT ? 4 : 1) + 65536;
    const auto space = fs::space(dir, ec);
    if ((two_file || ext_lc == ".nii" || cls == "MINCImageIO") && !ec && double(space.available) < bytes)
        fail_write(path, "not enough free space in folder " + quoted(dir.string()) + " (" +
                             bytes_text(double(space.available)) + " free, about " + bytes_text(bytes) + " needed)");

    // Written to a hidden temporary next to the target, checked, then renamed over the target.
    // Every failure below removes the temporaries (AtomicFile's destructor).
    AtomicFile out(target);
    const std::string tmp = out.temp_path().string();
    try {
        out.create();  // a clear reason (permissions, read-only file system) before ITK tries
        io->SetFileName(tmp);
        {
            const io_detail::SilencedStderr quiet;  // niftilib/teem print their own error first
            io->Write(data);
        }
        // Without orientation only where codes 0 say the same geometry (ITK reads them as the LPS
        // identity at the origin; an image placed otherwise, e.g. an MGH read with default axes,
        // keeps its placement and codes).
        const bool as_read_unoriented = lattice.direction() == kIdentity3 && lattice.origin() == Vec3d{0, 0, 0};
        if (!options.orientation_known && cls == "NiftiImageIO" && as_read_unoriented && !io_detail::clear_nifti_orientation(tmp))
            fail_write(path, "cannot mark the written header as without orientation");
        // Read the temporary back: catches writers that do not report short writes (disk full).
        auto check = create_io(tmp, itk::IOFileModeEnum::ReadMode);
        if (!check) fail_write(path, "the written file cannot be read back (disk full?)");
        check->SetFileName(tmp);
        check->ReadImageInformation();
        for (unsigned a = 0; a < 3; ++a)
            if (check->GetDimensions(a) != static_cast<itk::SizeValueType>(d[static_cast<int>(a)]))
                fail_write(path, "the written file does not read back with the same size (disk full?)");
        const io_detail::DataCheck data_check = check_data(*check, tmp, false);
        if (data_check.truncated) fail_write(path, "the file came out short, " + data_check.detail + " (disk full?)");
        out.commit(two_file);
    } catch (const ImageIoError&) {
        throw;
    } catch (const itk::ExceptionObject& e) {
        fail_write(path, condense(e, tmp));
    } catch (const std::exception& e) {
        fail_write(path, e.what());
    }
}

}  // namespace

void write_image(const Grid<float>& image, const std::string& path, const WriteOptions& options) {
    write_grid(image.values().data(), Component::FLOAT, image.lattice(), path, options);
}

void write_label_image(const Grid<std::uint8_t>& labels, const std::string& path, const WriteOptions& options) {
    write_grid(labels.values().data(), Component::UCHAR, labels.lattice(), path, options);
}

}  // namespace liveset
