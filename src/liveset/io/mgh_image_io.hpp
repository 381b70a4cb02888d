// FreeSurfer's MGH volumes (.mgh; .mgz or .mgh.gz compressed) as an ITK ImageIO, driven by image_io.cpp like
// ITK's own (Debian's ITK lacks the MGHIO remote module). Internal to liveset_io.
//
// The format (FreeSurfer's mghRead/mghWrite; nibabel.freesurfer.mghformat): a big-endian header of
// 284 bytes — version 1, width, height, depth, frames, type (0 uchar, 1 int32, 3 float32, 4 int16),
// dof, goodRASflag, then, where that flag is set, the voxel sizes, the three axes' direction cosines
// in RAS (x_r x_a x_s, y_r ..., z_r ...) and the RAS of the centre voxel (dims / 2) — then the
// voxels, x fastest, big-endian; an optional footer (scan parameters, tags) follows and is ignored.
// The world is RAS: it is converted to ITK's LPS on read and back on write. A header whose flag is
// not positive gives no orientation (orientation_known() false; FreeSurfer's test — nibabel uses
// the header for any nonzero flag) and reads with nibabel's default for it: 1 mm voxels, its
// default axes (x→L, y→S, z→P; FreeSurfer's own default may differ), centred. Written files hold one frame of uchar or float32 voxels, the flag set.
#pragma once

#include <itkImageIOBase.h>

#include <cstdint>
#include <string>

namespace liveset::io_detail {

// True when the file name ends in .mgh, .mgz or .mgh.gz (any case): image_io.cpp then uses MghImageIO.
bool is_mgh_name(const std::string& path);

class MghImageIO : public itk::ImageIOBase {
public:
    ITK_DISALLOW_COPY_AND_MOVE(MghImageIO);
    using Self = MghImageIO;
    using Superclass = itk::ImageIOBase;
    using Pointer = itk::SmartPointer<Self>;
    itkNewMacro(Self);
    itkTypeMacro(MghImageIO, ImageIOBase);

    bool SupportsDimension(unsigned long dim) override { return dim == 3 || dim == 4; }
    bool CanReadFile(const char* path) override;
    void ReadImageInformation() override;  // std::invalid_argument: another version or voxel type (one line, for the user)
    void Read(void* buffer) override;  // the whole image (every frame); throws std::runtime_error when short
    bool CanWriteFile(const char* path) override;
    void WriteImageInformation() override {}
    void Write(const void* buffer) override;  // 3D, uchar or float32; throws std::runtime_error on failure

    bool orientation_known() const { return orientation_known_; }

protected:
    MghImageIO();
    ~MghImageIO() override = default;

private:
    bool orientation_known_ = true;
    int type_ = 3;  // the file's MRI type code
};

}  // namespace liveset::io_detail
