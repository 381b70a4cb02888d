// Image IO: reads 3D medical images (NIfTI, MetaImage, NRRD, MINC, DICOM series) into Grids and
// writes Grids back, through ITK (with preprocess/, liveset's only ITK user); this header includes no ITK.
//
// Geometry follows ITK: world = origin + D * (spacing ⊙ ijk) in LPS, exactly as Lattice does, so
// outputs overlay their inputs in ITK-SNAP, 3D Slicer and FSLeyes.
//
// Every failure throws ImageIoError with a one-line message naming the path, e.g.
//   cannot read "t1.nii.gz": no such file or folder
//   cannot read "x.nii": file is corrupt or truncated (...)
//   cannot write "out/seg.nii.gz": folder "out" does not exist
//
// Safe to call from several threads (ITK's IO factories are registered once, on first use); a
// DICOM folder scan briefly switches ITK's global warning output off.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct ImageIoError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// What an image file says about itself (read without touching the pixels).
struct ImageHeader {
    Vec3i dims{0, 0, 0};      // sizes of the first three axes (1 for axes a 2D image lacks)
    Vec3d spacing{1, 1, 1};   // of the first three axes
    Vec3d origin{0, 0, 0};
    Mat3d direction = kIdentity3;  // upper-left 3x3 block of the file's direction matrix
    int dimension = 0;        // number of axes stored in the file (2, 3, 4, ...)
    int components = 1;       // values per voxel (3 for RGB)
    std::string pixel_type;   // stored type: "short", "float", ...; "rgb of unsigned_char" etc. if not scalar
    std::string format;       // "NIfTI", "MetaImage", "NRRD", "MINC", "DICOM", "DICOM series", ...
    // False when the header gives no orientation (a NIfTI with qform and sform codes 0, an Analyze
    // file): the axes are read as LPS identity, which may not be where the head's top is.
    bool orientation_known = true;
};

// Default refusal threshold for read_image / read_label_image: the image, held as one float per
// voxel, must fit in this many bytes (checked from the header, before anything is allocated).
inline constexpr std::uint64_t kDefaultImageMemoryLimit = std::uint64_t{8} << 30;  // 8 GiB

// Header of an image file or of a DICOM series folder (the series read_image would read).
// Throws only when the header itself cannot be read; it does not judge whether liveset can use
// the image (2D, RGB, ... are reported, not refused).
ImageHeader read_image_header(const std::string& path);

// Reads a scalar 3D image (any stored pixel type, converted to float). `path` is a file or a
// folder holding a DICOM series; a folder with several series yields the series with the most
// files (the header's `format` then says "DICOM series (largest of N)").
// Refuses, with ImageIoError: missing / unreadable / unknown-format / corrupt files, 2D images
// (also a single slice: some axis of size 1), 4D+ images unless the extra axes have size 1,
// multi-component (RGB, vector) images, empty images, images larger than kMaxLatticePoints or
// `max_bytes` (as float), non-positive or non-finite spacing, non-finite origin, singular
// direction, and NaN/infinite voxels ("N voxels are NaN or infinite"; with NanVoxels::keep,
// infinite ones only: "N voxels are infinite").
// `header` (optional) receives the header read_image_header would give.
enum class NanVoxels {
    refuse,  // a φ, a mask: NaN is damage
    keep,    // a scan: NaN is a masked image's "no data" (SPM, fslmaths -nan), read as NaN (a NIfTI's
             // too, which niftilib would read as 0)
};
Grid<float> read_image(const std::string& path, std::uint64_t max_bytes = kDefaultImageMemoryLimit, ImageHeader* header = nullptr,
                       NanVoxels nan = NanVoxels::refuse);

// Reads an integer label image (values 0..255; for masks nonzero means foreground). Same checks
// as read_image, plus: every value must be an integer in 0..255.
Grid<std::uint8_t> read_label_image(const std::string& path, std::uint64_t max_bytes = kDefaultImageMemoryLimit,
                                    ImageHeader* header = nullptr);

// Write with the full geometry (spacing, origin, direction). The format follows the extension:
// .nii.gz (recommended), .nii, .mha, .mhd (+ .raw), .nrrd, .nhdr (+ .raw), .mnc, or any other
// extension an ITK writer accepts (not DICOM). Floats are stored as float32, labels as uint8;
// .mha and .nrrd are zlib-compressed (lossless).
//
// Atomic: the image is written to a hidden temporary in the target folder that keeps the
// extension (".name.tmp-<pid>-<n>.nii.gz"), read back (header and data length: catches writers
// that ignore a full disk), flushed with fsync and renamed over the target, so the target is
// either the old file or the complete new one. Two-file formats (.mhd/.nhdr + .raw) are written
// the same way; the header's data-file reference is rewritten to the final name and the data
// file is renamed first, the header last (the header is the commit point; a stale .raw/.zraw
// of another name is left alone). Uncompressed output (.nii, .mhd, .nhdr) and MINC are refused
// up front when the folder lacks the space. On any failure the temporaries are removed and
// ImageIoError is thrown ("cannot write "<path>": folder "x" does not exist", "cannot create a
// file in folder ...", "not enough free space ...", "the file came out short ...").
//
// `options.orientation_known` false (the image's source gave none: ImageHeader::orientation_known):
// a NIfTI (.nii, .nii.gz) is written with qform and sform codes 0, as its source
// was, so that the tools that place such a file by a rule of their own (nibabel, FSL, FreeSurfer:
// from pixdim, x flipped) put the two in the same place; ITK-based tools (ITK-SNAP, 3D Slicer)
// read both as the LPS identity. Only where the lattice is that identity at the origin (as ITK
// reads such a NIfTI): a lattice placed otherwise (an MGH without its flag, read with default
// axes) keeps its placement and codes. Other formats store the lattice as it is.
struct WriteOptions {
    bool orientation_known = true;
};
void write_image(const Grid<float>& image, const std::string& path, const WriteOptions& options = {});
void write_label_image(const Grid<std::uint8_t>& labels, const std::string& path, const WriteOptions& options = {});

// True when `path` is a folder holding at least one DICOM series.
bool is_dicom_series_dir(const std::string& path);

}  // namespace liveset
