// Triangle-mesh value types shared by the marching-cubes code, the fragment mesher, the analysis
// utilities and the writers: a GPU-friendly Vertex (position + normal, 24 bytes) and an indexed
// mesh (vertex array V and triangle index array T, three uint32 indices per triangle).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

namespace liveset {

// A mesh vertex in lattice INDEX space (unit spacing): usable directly as a GPU vertex buffer.
struct Vertex {
    float position[3];
    float normal[3];  // unit length, pointing towards φ > 0 (outside)
};
static_assert(sizeof(Vertex) == 24 && std::is_standard_layout_v<Vertex> && std::is_trivially_copyable_v<Vertex>);

// Read-only view of an indexed triangle mesh (e.g. one fragment's V and T).
struct MeshView {
    std::span<const Vertex> vertices;
    std::span<const std::uint32_t> indices;  // 3 per triangle, counter-clockwise seen from outside

    std::size_t triangle_count() const { return indices.size() / 3; }
};

struct Mesh {
    std::vector<Vertex> vertices;
    std::vector<std::uint32_t> indices;

    std::size_t triangle_count() const { return indices.size() / 3; }
    MeshView view() const { return {vertices, indices}; }
    operator MeshView() const { return view(); }  // NOLINT(google-explicit-constructor)
    void clear() {
        vertices.clear();
        indices.clear();
    }
};

}  // namespace liveset
