// Test helper: writes a Grid as a DICOM series (one file per slice) with ITK's GDCM writer, so the
// DICOM reading path is tested against output liveset_io did not produce itself.
#pragma once

#include <string>

#include "liveset/grid/grid.hpp"

namespace liveset::test {

// Writes `image` (values rounded to int16) as slice_000.dcm, slice_001.dcm, ... into `folder`
// (which must exist), one series with the UID suffix `series` (use different ones for several
// series in one folder); `prefix` names the files.
void write_dicom_series(const Grid<float>& image, const std::string& folder, int series,
                        const std::string& prefix = "slice");

}  // namespace liveset::test
