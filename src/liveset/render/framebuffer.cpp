// Framebuffer objects: creation, binding, read-back and blits.
#include "liveset/render/framebuffer.hpp"

#include <stdexcept>
#include <string>
#include <utility>

namespace liveset::render {

Framebuffer::Framebuffer(int width, int height) { resize(width, height); }

Framebuffer::~Framebuffer() { release(); }

Framebuffer::Framebuffer(Framebuffer&& other) noexcept { *this = std::move(other); }

Framebuffer& Framebuffer::operator=(Framebuffer&& other) noexcept {
    if (this != &other) {
        release();
        width_ = std::exchange(other.width_, 0);
        height_ = std::exchange(other.height_, 0);
        id_ = std::exchange(other.id_, 0);
        color_ = std::exchange(other.color_, 0);
        depth_ = std::exchange(other.depth_, 0);
    }
    return *this;
}

void Framebuffer::release() {
    if (id_) glDeleteFramebuffers(1, &id_);
    if (color_) glDeleteTextures(1, &color_);
    if (depth_) glDeleteRenderbuffers(1, &depth_);
    id_ = color_ = depth_ = 0;
    width_ = height_ = 0;
}

bool Framebuffer::resize(int width, int height) {
    if (width == width_ && height == height_ && id_ != 0) return false;
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw std::runtime_error("bad framebuffer size " + std::to_string(width) + "x" + std::to_string(height));
    release();
    glGenTextures(1, &color_);
    glBindTexture(GL_TEXTURE_2D, color_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenRenderbuffers(1, &depth_);
    glBindRenderbuffer(GL_RENDERBUFFER, depth_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glGenFramebuffers(1, &id_);
    glBindFramebuffer(GL_FRAMEBUFFER, id_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        release();
        throw std::runtime_error("the OpenGL driver refuses an RGBA8 + depth24 framebuffer");
    }
    width_ = width;
    height_ = height;
    return true;
}

void Framebuffer::bind() const {
    glBindFramebuffer(GL_FRAMEBUFFER, id_);
    glViewport(0, 0, width_, height_);
}

Image read_bound_color(int width, int height) {
    Image img{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4)};
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
    // OpenGL rows run bottom to top: flip.
    const std::size_t row = static_cast<std::size_t>(width) * 4;
    std::vector<std::uint8_t> tmp(row);
    for (int y = 0; y < height / 2; ++y) {
        std::uint8_t* a = img.rgba.data() + static_cast<std::size_t>(y) * row;
        std::uint8_t* b = img.rgba.data() + static_cast<std::size_t>(height - 1 - y) * row;
        std::copy(a, a + row, tmp.data());
        std::copy(b, b + row, a);
        std::copy(tmp.data(), tmp.data() + row, b);
    }
    return img;
}

Image Framebuffer::read_color() const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, id_);
    Image img = read_bound_color(width_, height_);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    return img;
}

float Framebuffer::read_depth(int x, int y) const {
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return 1.0f;
    float depth = 1.0f;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, id_);
    glReadPixels(x, y, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &depth);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    return depth;
}

void Framebuffer::blit_to(GLuint target, int x, int y) const {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, id_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target);
    glBlitFramebuffer(0, 0, width_, height_, x, y, x + width_, y + height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace liveset::render
