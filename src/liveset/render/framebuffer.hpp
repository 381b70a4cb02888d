// An offscreen render target: an RGBA8 colour texture plus a 24-bit depth buffer in one OpenGL
// framebuffer object. Each viewer pane draws into its own (so a pane is redrawn only when it
// changed), headless mode draws the whole window into one, and picking reads its depth.
#pragma once

#include <epoxy/gl.h>

#include <cstdint>
#include <vector>

namespace liveset::render {

// An RGBA image, rows top to bottom (as PNG stores them).
struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgba;
};

class Framebuffer {
public:
    Framebuffer() = default;
    // Throws std::runtime_error when the driver refuses the format or the size.
    Framebuffer(int width, int height);
    ~Framebuffer();
    Framebuffer(Framebuffer&& other) noexcept;
    Framebuffer& operator=(Framebuffer&& other) noexcept;
    Framebuffer(const Framebuffer&) = delete;
    Framebuffer& operator=(const Framebuffer&) = delete;

    // Re-creates the buffers when the size differs (contents are then undefined); true if it did.
    bool resize(int width, int height);
    int width() const { return width_; }
    int height() const { return height_; }
    bool valid() const { return id_ != 0; }
    GLuint id() const { return id_; }
    GLuint color_texture() const { return color_; }

    // Binds for drawing and sets the viewport to the whole buffer.
    void bind() const;
    // The colour buffer (rows top to bottom).
    Image read_color() const;
    // Depth in [0, 1] at pixel (x, y), y counted from the BOTTOM row (OpenGL's convention).
    float read_depth(int x, int y) const;
    // Copies the colour into the currently bound draw framebuffer at (x, y) (bottom-left origin).
    void blit_to(GLuint target, int x, int y) const;

private:
    void release();
    int width_ = 0, height_ = 0;
    GLuint id_ = 0, color_ = 0, depth_ = 0;
};

// Reads the colour of the currently bound read framebuffer (e.g. a window's back buffer).
Image read_bound_color(int width, int height);

}  // namespace liveset::render
