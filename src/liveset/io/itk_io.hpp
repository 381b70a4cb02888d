// The ITK side shared by image reading (image_io.cpp) and writing (image_write.cpp): the IO
// factories, one-line errors, MINC's and Analyze's reader settings, the raw-data checks. Private to
// liveset_io (it includes ITK; image_io.hpp does not).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <itkMacro.h>
#include <itkImageIOBase.h>

#include "liveset/io/file_checks.hpp"

namespace liveset::io_detail {

// Registers the image IO factories liveset supports, once per process, in priority order.
void register_factories();

// The ImageIO for `path`: FreeSurfer's MGH by its name (.mgh, .mgz), else the registered factories'
// choice (null when none takes it).
itk::ImageIOBase::Pointer create_io(const std::string& path, itk::IOFileModeEnum mode);

// Throw ImageIoError "cannot read|write PATH: WHAT".
[[noreturn]] void fail_read(const std::string& path, const std::string& what);
[[noreturn]] void fail_write(const std::string& path, const std::string& what);

// An ITK exception's description as one line naming `path` (messages.hpp).
std::string condense(const itk::ExceptionObject& e, const std::string& path);

bool is_minc(const itk::ImageIOBase& io);
// Reader and writer settings: MINC's world kept as stored (RAS; flip_ras_lps converts it), Analyze
// read as ITK 4 read it.
void prepare_io(itk::ImageIOBase& io);

// What ITK's readers would hide: a short NIfTI is zero-filled and its NaN/Inf floats become 0, a
// short MetaImage only prints a warning. `io` has read the header of `file`. `nan_at`: as
// check_nifti_data's.
DataCheck check_data(const itk::ImageIOBase& io, const std::string& file, bool count_non_finite,
                     std::vector<std::uint8_t>* nan_at = nullptr);
// Whether check_data(io, file, true) may run beside ITK's read of `file`: it would decompress or
// stream a NIfTI's float data once more, and that data is all there (nifti_float_data_complete).
bool data_check_may_overlap(const itk::ImageIOBase& io, const std::string& file);

}  // namespace liveset::io_detail
