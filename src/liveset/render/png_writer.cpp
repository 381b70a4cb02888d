// PNG encode/decode with stb (the compiled implementations come from libstb).
#include "liveset/render/png_writer.hpp"

#include "liveset/base/atomic_file.hpp"

#include <stb_image.h>
#include <stb_image_write.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace liveset::render {

void write_png(const std::string& path, const Image& image) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const auto fail = [&](const std::string& why) { throw std::runtime_error("cannot write \"" + path + "\": " + why); };
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) fail("folder \"" + dir.string() + "\" does not exist");
    if (fs::is_directory(target, ec)) fail("it is a folder");
    if (image.width < 1 || image.height < 1 ||
        image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4)
        fail("empty or inconsistent image");
    std::string why;  // the reason of a failure; the temporary is gone when `file` is
    try {
        AtomicFile file(target);
        errno = 0;
        if (stbi_write_png(file.temp_path().c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4))
            file.commit();
        else
            why = errno ? std::strerror(errno) : "the PNG encoder failed";
    } catch (const std::runtime_error& e) {
        why = e.what();
    }
    if (!why.empty()) fail(why);
}

Image read_png(const std::string& path) {
    int w = 0, h = 0, n = 0;
    stbi_uc* data = stbi_load(path.c_str(), &w, &h, &n, 4);
    if (data == nullptr) {
        const char* why = stbi_failure_reason();
        throw std::runtime_error("cannot read \"" + path + "\": " + (why ? why : "not a PNG"));
    }
    Image img{w, h, std::vector<std::uint8_t>(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4)};
    stbi_image_free(data);
    return img;
}

Image downsample(const Image& image, int factor) {
    if (factor <= 1) return image;
    Image out{image.width / factor, image.height / factor, {}};
    out.rgba.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 4);
    const int area = factor * factor;
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                int sum = 0;
                for (int dy = 0; dy < factor; ++dy)
                    for (int dx = 0; dx < factor; ++dx)
                        sum += image.rgba[(static_cast<std::size_t>(y * factor + dy) * static_cast<std::size_t>(image.width) +
                                           static_cast<std::size_t>(x * factor + dx)) * 4 + static_cast<std::size_t>(c)];
                out.rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x)) * 4 +
                         static_cast<std::size_t>(c)] = static_cast<std::uint8_t>((sum + area / 2) / area);
            }
    return out;
}

}  // namespace liveset::render
