// Per-fragment GPU buffers.
#include "liveset/render/surface_buffers.hpp"

#include <algorithm>

namespace liveset::render {

SurfaceBuffers::~SurfaceBuffers() { release(); }

void SurfaceBuffers::release() {
    for (FragmentBuffers& f : fragments_) {
        if (f.vao) glDeleteVertexArrays(1, &f.vao);
        if (f.vbo) glDeleteBuffers(1, &f.vbo);
        if (f.ibo) glDeleteBuffers(1, &f.ibo);
    }
    fragments_.clear();
    triangles_ = 0;
}

UploadStats SurfaceBuffers::upload(const FragmentMesher& mesher, std::span<const FragmentId> ids) {
    if (fragments_.size() != mesher.fragment_count()) return upload_all(mesher);
    UploadStats stats;
    for (FragmentId id : ids) {
        const FragmentView view = mesher.fragment(id);
        FragmentBuffers& f = fragments_[id];
        const auto vbytes = static_cast<GLsizeiptr>(view.vertices.size_bytes());
        if (f.vao && f.topology != 0 && view.topology == f.topology && view.vertices.size() == f.vertices) {
            glBindBuffer(GL_ARRAY_BUFFER, f.vbo);  // the same T: the moved vertices only, in place
            glBufferSubData(GL_ARRAY_BUFFER, 0, vbytes, view.vertices.data());
            ++stats.fragments;
            ++stats.vertices_only;
            stats.bytes += static_cast<std::size_t>(vbytes);
            continue;
        }
        triangles_ -= static_cast<std::size_t>(f.indices) / 3;
        if (view.indices.empty()) {
            f.indices = 0;  // keep the (now unused) buffers for the fragment's next triangles
            f.topology = 0;
            continue;
        }
        if (!f.vao) {
            glGenVertexArrays(1, &f.vao);
            glGenBuffers(1, &f.vbo);
            glGenBuffers(1, &f.ibo);
            glBindVertexArray(f.vao);
            glBindBuffer(GL_ARRAY_BUFFER, f.vbo);
            glEnableVertexAttribArray(0);
            glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, position)));
            glEnableVertexAttribArray(1);
            glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, normal)));
            glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, f.ibo);  // recorded in the vertex array
        } else {
            glBindVertexArray(f.vao);
            glBindBuffer(GL_ARRAY_BUFFER, f.vbo);
        }
        const auto ibytes = static_cast<GLsizeiptr>(view.indices.size_bytes());
        glBufferData(GL_ARRAY_BUFFER, vbytes, view.vertices.data(), GL_DYNAMIC_DRAW);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, ibytes, view.indices.data(), GL_DYNAMIC_DRAW);
        f.indices = static_cast<GLsizei>(view.indices.size());
        f.vertices = view.vertices.size();
        f.topology = view.topology;
        triangles_ += view.indices.size() / 3;
        ++stats.fragments;
        stats.bytes += static_cast<std::size_t>(vbytes + ibytes);
    }
    glBindVertexArray(0);
    uploads_ += stats.fragments;
    return stats;
}

UploadStats SurfaceBuffers::upload_all(const FragmentMesher& mesher) {
    release();
    fragments_.resize(mesher.fragment_count());
    std::vector<FragmentId> all(mesher.fragment_count());
    for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
    return upload(mesher, all);
}

void SurfaceBuffers::draw() const {
    for (const FragmentBuffers& f : fragments_) {
        if (f.indices == 0) continue;
        glBindVertexArray(f.vao);
        glDrawElements(GL_TRIANGLES, f.indices, GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
}

Bounds surface_bounds(const FragmentMesher& mesher) {
    const glm::dmat4 m = index_to_world(mesher.lattice());
    glm::dvec3 lo(1e300), hi(-1e300);
    bool any = false;
    for (FragmentId f = 0; f < mesher.fragment_count(); ++f)
        for (const Vertex& v : mesher.fragment(f).vertices) {
            const glm::dvec3 w(m * glm::dvec4(v.position[0], v.position[1], v.position[2], 1.0));
            lo = glm::min(lo, w);
            hi = glm::max(hi, w);
            any = true;
        }
    if (!any) return world_bounds(mesher.lattice());
    Bounds b;
    b.centre = 0.5 * (lo + hi);
    b.radius = std::max(0.5 * glm::length(hi - lo), 1.0);
    return b;
}

}  // namespace liveset::render
