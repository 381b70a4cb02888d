// The ITK side shared by image reading (image_io.cpp) and writing (image_write.cpp): see itk_io.hpp.
#include "liveset/io/itk_io.hpp"

#include <mutex>
#include <string>

#include <itkGDCMImageIOFactory.h>
#include <itkImageIOFactory.h>
#include <itkMINCImageIO.h>
#include <itkMINCImageIOFactory.h>
#include <itkMetaImageIOFactory.h>
#include <itkNiftiImageIO.h>
#include <itkNiftiImageIOFactory.h>
#include <itkNrrdImageIOFactory.h>

#include "liveset/io/image_io.hpp"
#include "liveset/io/messages.hpp"
#include "liveset/io/mgh_image_io.hpp"

namespace liveset::io_detail {

// ---------------------------------------------------------------------------------------------
// Factories and messages

// Registers the image IO factories liveset supports, once per process, in priority order. Done
// here explicitly (not through UseITK's static registration header) so it cannot be dropped by
// the linker or depend on static initialisation order in a static library.
void register_factories() {
    static std::once_flag once;
    std::call_once(once, [] {
        itk::NiftiImageIOFactory::RegisterOneFactory();
        itk::MetaImageIOFactory::RegisterOneFactory();
        itk::NrrdImageIOFactory::RegisterOneFactory();
        itk::MINCImageIOFactory::RegisterOneFactory();
        itk::GDCMImageIOFactory::RegisterOneFactory();
    });
}

// The ImageIO for `path`: FreeSurfer's MGH by its name (.mgh, .mgz; ours, mgh_image_io.hpp), else
// the registered factories' choice (null when none takes it). A file that claims to be MGH and is
// not still gets the MGH reader, whose error then says why.
itk::ImageIOBase::Pointer create_io(const std::string& path, itk::IOFileModeEnum mode) {
    if (is_mgh_name(path)) return MghImageIO::New().GetPointer();
    return itk::ImageIOFactory::CreateImageIO(path.c_str(), mode);
}

[[noreturn]] void fail_read(const std::string& path, const std::string& what) {
    throw ImageIoError("cannot read " + quoted(path) + ": " + what);
}
[[noreturn]] void fail_write(const std::string& path, const std::string& what) {
    throw ImageIoError("cannot write " + quoted(path) + ": " + what);
}

std::string condense(const itk::ExceptionObject& e, const std::string& path) {
    return condense(e.GetDescription(), path);
}

// ---------------------------------------------------------------------------------------------
// MINC: its RAS world is converted to LPS on read and back on write (minc_world.hpp says why)

bool is_minc(const itk::ImageIOBase& io) { return std::string(io.GetNameOfClass()) == "MINCImageIO"; }

// Later ITK releases can convert MINC's RAS to LPS themselves (SetRAStoLPS): switched off where
// it exists, so that flip_ras_lps below is the one conversion.
template <class MincIO>
void keep_minc_world_as_stored(MincIO& io) {
    if constexpr (requires { io.SetRAStoLPS(false); }) io.SetRAStoLPS(false);
}

void prepare_io(itk::ImageIOBase& io) {
    if (auto* minc = dynamic_cast<itk::MINCImageIO*>(&io)) keep_minc_world_as_stored(*minc);
    // An Analyze file is read as ITK 4 read it (the axes as stored, no orientation: orientation_known
    // false), without the default flavour's multi-line deprecation warning on stderr.
    if (auto* nifti = dynamic_cast<itk::NiftiImageIO*>(&io)) nifti->SetLegacyAnalyze75Mode(itk::NiftiImageIOEnums::Analyze75Flavor::AnalyzeITK4);
}

// What ITK's readers would hide: a short NIfTI is zero-filled and its NaN/Inf floats become 0, a
// short MetaImage only prints a warning. `io` has read the header of `file`.
// `nan_at`: as check_nifti_data's.
DataCheck check_data(const itk::ImageIOBase& io, const std::string& file, bool count_non_finite,
                      std::vector<std::uint8_t>* nan_at) {
    const std::string cls = io.GetNameOfClass();
    if (cls == "NiftiImageIO") return check_nifti_data(file, count_non_finite, nan_at);
    if (cls == "MetaImageIO") {
        std::uint64_t bytes = io.GetComponentSize() * io.GetNumberOfComponents();
        for (unsigned a = 0; a < io.GetNumberOfDimensions(); ++a) bytes *= io.GetDimensions(a);
        return check_metaimage_data(file, bytes);
    }
    return {};
}

bool data_check_may_overlap(const itk::ImageIOBase& io, const std::string& file) {
    return std::string(io.GetNameOfClass()) == "NiftiImageIO" && nifti_float_data_complete(file);
}

}  // namespace liveset::io_detail
