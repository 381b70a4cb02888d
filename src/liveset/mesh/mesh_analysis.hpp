// Mesh analysis utilities used by the tests and by evaluation: welding by quantised position,
// edge/manifold statistics, Euler characteristic, connected components, area, enclosed volume,
// normal sanity checks and a canonical triangle set for comparing meshes built differently.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "liveset/mesh/mesh.hpp"

namespace liveset {

// Merges vertices whose positions round to the same multiple of `quantum` (per coordinate);
// bit-identical positions always merge. Keeps the first vertex's normal, drops triangles that
// become degenerate (two equal indices) and vertices no triangle references.
Mesh weld_vertices(MeshView mesh, double quantum = 1e-4);

struct EdgeStats {
    std::size_t edges = 0;               // distinct undirected edges
    std::size_t boundary_edges = 0;      // used by exactly 1 triangle
    std::size_t nonmanifold_edges = 0;   // used by 3 or more triangles
    std::size_t misoriented_edges = 0;   // 2 triangles traversing the edge in the same direction
    std::size_t degenerate_triangles = 0;  // repeated vertex index
    bool closed_manifold() const {
        return boundary_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 && degenerate_triangles == 0;
    }
};
// Edge statistics on the mesh's indices as given (weld first to merge duplicated vertices).
EdgeStats edge_stats(MeshView mesh);
// Undirected edges (a < b) used by a number of triangles other than 2.
std::vector<std::array<std::uint32_t, 2>> edges_not_shared_by_two(MeshView mesh);

// V - E + F over referenced vertices, on the indices as given.
long long euler_characteristic(MeshView mesh);
// Connected components of the triangle graph (triangles sharing a vertex index).
std::size_t connected_components(MeshView mesh);
// Vertices whose incident triangles do not form a single fan (pinched vertices); 0 on a 2-manifold.
std::size_t nonmanifold_vertices(MeshView mesh);

double surface_area(MeshView mesh);
// Signed volume by the divergence theorem: positive for a closed mesh wound counter-clockwise
// seen from outside.
double enclosed_volume(MeshView mesh);

// Vertices whose normal has a NaN/inf component or a length outside [1 - tol, 1 + tol].
std::size_t invalid_normal_count(MeshView mesh, double tol = 1e-3);
// Vertices with a NaN/inf position component.
std::size_t invalid_position_count(MeshView mesh);

// Canonical, orientation-preserving triangle set: each triangle as three quantised positions,
// rotated so the smallest comes first; the list sorted. Equal for two meshes holding the same
// triangles whatever their vertex sharing or triangle order.
using QuantisedPoint = std::array<std::int64_t, 3>;
using CanonicalTriangle = std::array<QuantisedPoint, 3>;
std::vector<CanonicalTriangle> canonical_triangles(MeshView mesh, double quantum = 1e-4);

// Concatenates meshes (indices offset).
Mesh concatenate(const std::vector<MeshView>& parts);

}  // namespace liveset
