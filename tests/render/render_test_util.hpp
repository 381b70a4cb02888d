// Shared pieces of the rendering tests: a small phantom session, one headless context per test
// program, and image comparison with a per-pixel tolerance.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>

#include "liveset/phantom/phantom.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/render/headless_context.hpp"
#include "liveset/session/session.hpp"

namespace liveset::testing {

inline render::HeadlessContext& gl_context() {
    static render::HeadlessContext context;  // one per process; EGL is cheap to keep
    return context;
}

// The default phantom of size N³, made once per test program.
template <int N>
const Phantom& phantom_of_size() {
    static const Phantom ph = [] {
        PhantomOptions o;
        o.size = N;
        return make_phantom(o);
    }();
    return ph;
}

inline const Phantom& phantom64() { return phantom_of_size<64>(); }

// A session on the 64^3 phantom with its grey-matter truth as the level set.
inline std::unique_ptr<Session> truth_session() {
    auto s = std::make_unique<Session>(phantom64().image, SessionOptions{});
    s->load_mask(phantom64().truth);
    return s;
}

struct ImageDifference {
    double mean_abs = 0.0;          // over all channels
    double fraction_over = 0.0;     // pixels with some channel differing by more than `tolerance`
    int max_abs = 0;
};

inline ImageDifference compare(const render::Image& a, const render::Image& b, int tolerance) {
    ImageDifference d;
    if (a.width != b.width || a.height != b.height) {
        d.mean_abs = 255.0;
        d.fraction_over = 1.0;
        d.max_abs = 255;
        return d;
    }
    std::size_t over = 0;
    double sum = 0.0;
    for (std::size_t p = 0; p < a.rgba.size() / 4; ++p) {
        int worst = 0;
        for (int c = 0; c < 4; ++c) {
            const int diff = std::abs(int(a.rgba[p * 4 + c]) - int(b.rgba[p * 4 + c]));
            sum += diff;
            worst = std::max(worst, diff);
        }
        d.max_abs = std::max(d.max_abs, worst);
        over += worst > tolerance;
    }
    d.mean_abs = sum / static_cast<double>(a.rgba.size());
    d.fraction_over = static_cast<double>(over) / static_cast<double>(a.rgba.size() / 4);
    return d;
}

// Fraction of pixels that differ from the colour of pixel (0, 0) (the background).
inline double covered_fraction(const render::Image& img) {
    std::size_t n = 0;
    for (std::size_t p = 0; p < img.rgba.size() / 4; ++p)
        for (int c = 0; c < 3; ++c)
            if (img.rgba[p * 4 + c] != img.rgba[c]) {
                ++n;
                break;
            }
    return static_cast<double>(n) / static_cast<double>(img.rgba.size() / 4);
}

}  // namespace liveset::testing
