// Internal to liveset_io: checks on the raw bytes of image files, for the cases where ITK's readers
// hide damage. niftilib zero-fills the missing part of a short file and silently replaces NaN and
// infinite floats by 0; MetaIO only prints a warning when a data file is short. And one patch ITK's
// NIfTI writer cannot be asked for (orientation codes 0). No ITK in here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace liveset::io_detail {

struct DataCheck {
    bool truncated = false;
    std::string detail;            // why, when truncated ("holds 1000 of 2772 data bytes")
    std::uint64_t non_finite = 0;  // NaN / infinite voxels counted (NIfTI float data only)
    std::uint64_t nan = 0;         // of which NaN
};

// NIfTI-1/-2 (.nii, .nii.gz; compressed or not), and two-file images (`path` either file of a
// .hdr/.img pair, each maybe .gz: NIfTI "ni1"/"ni2" or Analyze 7.5, which niftilib reads too): the
// data the header promises is all there; with count_non_finite, NaN and infinite values of
// float32/float64 data are counted (which means decompressing the file once more).
// `nan_at` (with count_non_finite): one flag per stored value, 1 where it is NaN, in file order
// (niftilib reads those as 0), up to the last chunk holding a NaN (shorter than the data: the rest
// holds none); left empty when the data holds no NaN.
DataCheck check_nifti_data(const std::string& path, bool count_non_finite, std::vector<std::uint8_t>* nan_at = nullptr);

// Whether check_nifti_data(path, true) would stream float data (float32/float64) that is all
// there by the file's size or, compressed, by its gzip trailer (the uncompressed size modulo 2^32):
// where the check reads data known to be complete, so that it can run beside ITK's read without
// ITK meeting a short file (damage the trailer cannot show, a corrupt middle, is still the check's
// to report). False for anything else (the check is then cheap, or may find a short file that ITK
// must not read first).
bool nifti_float_data_complete(const std::string& path);

// MetaImage (.mha with LOCAL data, .mhd with one data file): the data file holds `raw_bytes`
// (uncompressed) or the header's CompressedDataSize. Multi-file (LIST, pattern) data is unchecked.
DataCheck check_metaimage_data(const std::string& path, std::uint64_t raw_bytes);

// Sets a NIfTI header's qform_code and sform_code to 0 (no orientation), in place: a .nii is
// patched, a .nii.gz streamed through a second temporary (`path`.orient) and renamed over it.
// NIfTI-1 and NIfTI-2. False when it is neither, or cannot be read or written (`path` then as it was).
bool clear_nifti_orientation(const std::string& path);

}  // namespace liveset::io_detail
