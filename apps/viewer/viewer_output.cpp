// Viewer outputs: mask, phi and mesh in the formats of `liveset segment` (written atomically by
// liveset_io / the mesh writer), screenshots of a pane or the whole window (PNG, atomic).
#include <algorithm>

#include "cli_support.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/render/png_writer.hpp"
#include "viewer.hpp"

namespace liveset::viewer {

bool Viewer::save_mask(const std::string& path) {
    halt_run();
    if (!session_) return fail("open an image first");
    try {
        cli::check_output_path(path, cli::OutputKind::kImage, "mask");
        write_label_image(session_->mask(), path, {.orientation_known = config_.image_oriented});
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    message_ = "saved the mask to " + path;
    message_is_error_ = false;
    log_.add("save", {{"what", "mask"}, {"path", path}});
    autosave_->mark_saved();
    saved_revision_ = session_->revision();
    return true;
}

bool Viewer::save_phi(const std::string& path) {
    halt_run();
    if (!session_) return fail("open an image first");
    try {
        cli::check_output_path(path, cli::OutputKind::kImage, "phi");
        write_image(session_->field().phi(), path, {.orientation_known = config_.image_oriented});
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    message_ = "saved phi to " + path;
    message_is_error_ = false;
    log_.add("save", {{"what", "phi"}, {"path", path}});
    autosave_->mark_saved();
    saved_revision_ = session_->revision();
    return true;
}

bool Viewer::save_mesh(const std::string& path) {
    halt_run();
    if (!session_) return fail("open an image first");
    try {
        cli::check_output_path(path, cli::OutputKind::kMesh, "mesh");
        write_mesh(path, session_->surface_mesh().view(), session_->lattice());
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    message_ = "saved the surface to " + path;
    message_is_error_ = false;
    log_.add("save", {{"what", "mesh"}, {"path", path}});
    return true;
}

render::Image Viewer::capture_pane(Pane pane, int width, int height, int supersample) {
    halt_run();
    const int ss = std::clamp(supersample, 1, 4);
    const Rect saved = pane_rects_[static_cast<int>(pane)];
    pane_rects_[static_cast<int>(pane)] = {saved.x, saved.y, width * ss, height * ss};
    upload();
    capturing_ = true;  // full quality, even during an interaction
    render_pane(pane);  // into the pane's own buffer at the capture size
    capturing_ = false;
    const render::Image img = pane_buffers_[static_cast<int>(pane)].read_color();
    pane_rects_[static_cast<int>(pane)] = saved;
    pane_dirty_[static_cast<int>(pane)] = true;  // back to the layout size on the next frame
    return render::downsample(img, ss);
}

render::Image Viewer::capture_window(int width, int height) {
    halt_run();
    render::Framebuffer fb(width, height);
    for (int k = 0; k < 2; ++k) frame(fb.id(), width, height, 1.0 / 60.0);  // ImGui lays out in one frame, settles in two
    return fb.read_color();
}

bool Viewer::save_screenshot(const std::string& path, std::optional<Pane> pane, int width, int height, int supersample) {
    halt_run();
    try {
        render::Image img;
        if (pane) {
            const Rect r = pane_rects_[static_cast<int>(*pane)];
            img = capture_pane(*pane, width > 0 ? width : std::max(r.w, 16), height > 0 ? height : std::max(r.h, 16), supersample);
        } else {
            img = capture_window(width > 0 ? width : std::max(window_width_, 64), height > 0 ? height : std::max(window_height_, 64));
        }
        render::write_png(path, img);
    } catch (const std::exception& e) {
        return fail(e.what());
    }
    message_ = "saved a screenshot to " + path;
    message_is_error_ = false;
    log_.add("screenshot", {{"path", path}, {"pane", pane ? pane_name(*pane) : "window"}});
    return true;
}

}  // namespace liveset::viewer
