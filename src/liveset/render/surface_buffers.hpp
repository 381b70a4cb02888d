// The surface on the GPU: one vertex buffer, one index buffer and one vertex array per mesh
// fragment, mirroring FragmentMesher's fragments. After an update only the fragments the mesher
// reports (U) are re-uploaded; drawing issues one call per non-empty fragment. Vertices stay in
// index space (24 bytes: position + ∇φ normal); the shader maps them to millimetres.
#pragma once

#include <epoxy/gl.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/render/volume_transform.hpp"

namespace liveset::render {

struct UploadStats {
    std::size_t fragments = 0;  // buffers re-uploaded
    std::size_t bytes = 0;      // vertex + index bytes sent
    std::size_t vertices_only = 0;  // of `fragments`: T unchanged (FragmentView::topology), only V sent
};

class SurfaceBuffers {
public:
    SurfaceBuffers() = default;
    ~SurfaceBuffers();
    SurfaceBuffers(const SurfaceBuffers&) = delete;
    SurfaceBuffers& operator=(const SurfaceBuffers&) = delete;

    // Re-uploads fragments `ids` of `mesher` (the list FragmentMesher::update returned); a fragment
    // whose T is the one uploaded last (same topology stamp) gets only its V, in place. The first
    // call, or one after the mesher's fragment count changed, sizes the buffer set to the mesher.
    UploadStats upload(const FragmentMesher& mesher, std::span<const FragmentId> ids);
    // Re-uploads every fragment.
    UploadStats upload_all(const FragmentMesher& mesher);
    // Draws every non-empty fragment with the program in use (attribute 0 position, 1 normal).
    void draw() const;

    std::size_t fragment_count() const { return fragments_.size(); }
    std::size_t triangle_count() const { return triangles_; }
    std::size_t uploads() const { return uploads_; }  // fragment uploads since creation

private:
    struct FragmentBuffers {
        GLuint vao = 0, vbo = 0, ibo = 0;
        GLsizei indices = 0;
        std::size_t vertices = 0;
        std::uint64_t topology = 0;  // FragmentView::topology of the T uploaded (0: none)
    };
    void release();
    std::vector<FragmentBuffers> fragments_;
    std::size_t triangles_ = 0;
    std::size_t uploads_ = 0;
};

// World-space sphere around the mesher's vertices (the lattice's bounds when it has none): what
// the 3D view frames, so the surface - not the empty field of view around it - fills the pane.
Bounds surface_bounds(const FragmentMesher& mesher);

}  // namespace liveset::render
