// Internal to liveset_io: MINC's world coordinates are RAS, liveset's (like ITK's) are LPS. No ITK in here.
//
// MINC stores positions in RAS (x towards the patient's right, y anterior, z superior). ITK 5.2's
// MINCImageIO does not convert them: for MINC1 and MINC2 files alike it hands over the xspace,
// yspace and zspace axes (in that order, each step made positive by reading the data reversed
// where the file's step is negative) with their RAS direction cosines and the RAS position of the
// first voxel, as if these were LPS, so a .mnc came out mirrored in x and y (checked against
// minc-tools by tests/io/minc_test.cpp). image_io.cpp therefore converts: after ITK has read a
// MINC header, the first two components of the origin and of every axis direction are negated
// (RAS -> LPS), and before ITK writes a .mnc the same negation turns liveset's LPS geometry into
// the RAS that minc-tools (mincinfo, worldtovoxel, mnc2nii) expect. Later ITK releases can convert
// by themselves (a RAStoLPS switch); image_io.cpp turns that switch off where it exists, so the
// conversion happens exactly once.
#pragma once

#include <vector>

namespace liveset::io_detail {

// RAS <-> LPS (the same negation both ways) of an origin and of axis directions as ITK's ImageIO
// gives or takes them: each with as many components as ITK has (a 2D file has two).
void flip_ras_lps(std::vector<double>& origin, std::vector<std::vector<double>>& axes);

}  // namespace liveset::io_detail
