// The coarse start's preview: while the session's coarse run is under way (φ still the seeds), the
// 3D pane draws that run's front meshed on its grid of 2x2x2 blocks, and the slice panes fill and
// outline its values upsampled onto the image's grid - where the fine run will start, but for the
// voxels the image's own data term refuses (CoarseRun::fine_start leaves those out).
#include <algorithm>
#include <chrono>
#include <cstring>

#include "viewer.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

namespace {

// The points whose φ differs (bits) between `now` and `before` (the same lattice), blocks of equal
// memory skipped whole: a coarse iteration moves a thin sheet of a grid of millions of points.
std::vector<PointIndex> changed_points(const Grid<float>& now, const Grid<float>& before) {
    constexpr std::size_t kBlock = 4096;
    std::vector<PointIndex> out;
    const float* a = now.values().data();
    const float* b = before.values().data();
    for (std::size_t lo = 0; lo < now.size(); lo += kBlock) {
        const std::size_t hi = std::min(now.size(), lo + kBlock);
        if (std::memcmp(a + lo, b + lo, (hi - lo) * sizeof(float)) == 0) continue;
        for (std::size_t i = lo; i < hi; ++i)
            if (std::memcmp(a + i, b + i, sizeof(float)) != 0) out.push_back(static_cast<PointIndex>(i));
    }
    return out;
}

}  // namespace

bool Viewer::refresh_coarse_preview(bool due) {
    const SparseField* coarse = session_ ? session_->coarse_field() : nullptr;
    if (!coarse) {  // dropped at once: the session's surface is what the panes show again
        if (!preview_mesher_) return false;
        preview_mesher_.reset();
        preview_surface_.reset();
        preview_phi_ = Grid<float>();
        ++preview_generation_;
        return true;
    }
    const bool fresh = !preview_mesher_ || !(preview_mesher_->lattice().dims() == coarse->phi().dims());
    if (!fresh && (!due || session_->coarse_serial() == preview_serial_)) return false;  // paced; or no coarse step since
    preview_serial_ = session_->coarse_serial();
    const Grid<float>& phi = coarse->phi();
    const auto t0 = std::chrono::steady_clock::now();
    if (fresh) {
        preview_mesher_ = std::make_unique<FragmentMesher>(phi.lattice(), session_->mesher().fragment_size());
        preview_mesher_->full_rebuild(phi, coarse->zero_layer());
        preview_phi_ = phi;
        const auto t1 = std::chrono::steady_clock::now();
        preview_surface_ = std::make_unique<render::SurfaceBuffers>();
        preview_surface_->upload_all(*preview_mesher_);
        current_.mesh_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        current_.upload_ms += ms_since(t1);
    } else {
        const std::vector<PointIndex> changed = changed_points(phi, preview_phi_);
        if (changed.empty()) return false;
        const std::vector<FragmentId> ids = preview_mesher_->update(phi, changed);
        for (const PointIndex p : changed) preview_phi_[p] = phi[p];
        const auto t1 = std::chrono::steady_clock::now();
        if (!ids.empty()) preview_surface_->upload(*preview_mesher_, ids);
        current_.mesh_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        current_.upload_ms += ms_since(t1);
    }
    ++preview_generation_;
    return true;
}

}  // namespace liveset::viewer
