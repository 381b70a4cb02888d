// PNG output of rendered images through stb_image_write, written atomically (a temporary file in
// the target folder, then a rename), and PNG input for the reference-image tests.
#pragma once

#include <string>

#include "liveset/render/framebuffer.hpp"

namespace liveset::render {

// Throws std::runtime_error ("cannot write "x.png": ...") when the folder is missing or not
// writable or the encoder fails; the target is then untouched.
void write_png(const std::string& path, const Image& image);

// Reads a PNG as RGBA (std::runtime_error naming the path on failure).
Image read_png(const std::string& path);

// Box-filters an image down by an integer factor (supersampled screenshots).
Image downsample(const Image& image, int factor);

}  // namespace liveset::render
