// The demos' pictures without a display (see demo_pictures.hpp).
#include "demo_pictures.hpp"

#include <fmt/core.h>

#include "liveset/render/surface_picture.hpp"

namespace liveset::cli {

nlohmann::json write_before_after_pictures(const std::filesystem::path& dir, const Grid<float>& phi_before,
                                           const FragmentMesher& after) {
    try {
        FragmentMesher before(phi_before.lattice(), after.fragment_size());
        before.full_rebuild(phi_before);
        render::render_surface_png(before, (dir / "before.png").string(), "superior", 800, 800, 2);
        render::render_surface_png(after, (dir / "after.png").string(), "superior", 800, 800, 2);
        return {{"before", "before.png"}, {"after", "after.png"}};
    } catch (const std::exception& e) {
        fmt::print(stderr, "liveset: warning: no before/after pictures: {}\n", e.what());
        return nullptr;
    }
}

}  // namespace liveset::cli
