// Test helper: DICOM series through ITK's GDCMImageIO and ImageSeriesWriter, with per-slice
// position / orientation / UID tags (as ITK's and SimpleITK's DICOM series examples do).
#include "dicom_writer.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include <itkGDCMImageIO.h>
#include <itkImage.h>
#include <itkImageSeriesWriter.h>
#include <itkMetaDataObject.h>

namespace liveset::test {

void write_dicom_series(const Grid<float>& grid, const std::string& folder, int series, const std::string& prefix) {
    using Image3 = itk::Image<short, 3>;
    using Image2 = itk::Image<short, 2>;
    const Lattice& lat = grid.lattice();
    const Vec3i d = lat.dims();

    auto image = Image3::New();
    Image3::RegionType region;
    region.SetSize({{static_cast<itk::SizeValueType>(d.x), static_cast<itk::SizeValueType>(d.y),
                     static_cast<itk::SizeValueType>(d.z)}});
    image->SetRegions(region);
    Image3::SpacingType spacing;
    Image3::PointType origin;
    Image3::DirectionType direction;
    for (int a = 0; a < 3; ++a) {
        spacing[a] = lat.spacing()[a];
        origin[a] = lat.origin()[a];
        for (int c = 0; c < 3; ++c) direction[a][c] = lat.direction()[static_cast<std::size_t>(a * 3 + c)];
    }
    image->SetSpacing(spacing);
    image->SetOrigin(origin);
    image->SetDirection(direction);
    image->Allocate();
    short* out = image->GetBufferPointer();
    for (std::size_t i = 0; i < grid.size(); ++i)
        out[i] = static_cast<short>(std::lround(grid[static_cast<PointIndex>(i)]));

    const std::string root = "1.2.826.0.1.3680043.2.1125.99.";
    const std::string study = root + "1";
    const std::string series_uid = root + "2." + std::to_string(series);
    std::ostringstream orientation;
    orientation.precision(12);
    orientation << direction[0][0] << "\\" << direction[1][0] << "\\" << direction[2][0] << "\\" << direction[0][1]
                << "\\" << direction[1][1] << "\\" << direction[2][1];

    std::vector<itk::MetaDataDictionary> dicts(static_cast<std::size_t>(d.z));
    itk::ImageSeriesWriter<Image3, Image2>::DictionaryArrayType dict_ptrs;
    std::vector<std::string> files;
    for (int z = 0; z < d.z; ++z) {
        itk::MetaDataDictionary& dict = dicts[static_cast<std::size_t>(z)];
        Image3::PointType p;
        image->TransformIndexToPhysicalPoint({{0, 0, z}}, p);
        std::ostringstream pos;
        pos.precision(12);
        pos << p[0] << "\\" << p[1] << "\\" << p[2];
        itk::EncapsulateMetaData<std::string>(dict, "0008|0060", "MR");
        itk::EncapsulateMetaData<std::string>(dict, "0008|0016", "1.2.840.10008.5.1.4.1.1.4");  // MR storage
        itk::EncapsulateMetaData<std::string>(dict, "0008|0018",
                                              series_uid + "." + std::to_string(z + 1));
        itk::EncapsulateMetaData<std::string>(dict, "0010|0010", "liveset^test");
        itk::EncapsulateMetaData<std::string>(dict, "0028|0004", "MONOCHROME2");
        itk::EncapsulateMetaData<std::string>(dict, "0020|000d", study);
        itk::EncapsulateMetaData<std::string>(dict, "0020|000e", series_uid);
        itk::EncapsulateMetaData<std::string>(dict, "0020|0011", std::to_string(series));
        itk::EncapsulateMetaData<std::string>(dict, "0020|0013", std::to_string(z + 1));
        itk::EncapsulateMetaData<std::string>(dict, "0020|0032", pos.str());
        itk::EncapsulateMetaData<std::string>(dict, "0020|0037", orientation.str());
        itk::EncapsulateMetaData<std::string>(dict, "0018|0050", std::to_string(spacing[2]));
        itk::EncapsulateMetaData<std::string>(dict, "0018|0088", std::to_string(spacing[2]));
        dict_ptrs.push_back(&dict);
        char name[64];
        std::snprintf(name, sizeof name, "/%s_%03d.dcm", prefix.c_str(), z);
        files.push_back(folder + name);
    }

    auto io = itk::GDCMImageIO::New();
    io->KeepOriginalUIDOn();
    auto writer = itk::ImageSeriesWriter<Image3, Image2>::New();
    writer->SetInput(image);
    writer->SetImageIO(io);
    writer->SetFileNames(files);
    writer->SetMetaDataDictionaryArray(&dict_ptrs);
    writer->Update();
}

}  // namespace liveset::test
