// Mesh export (PLY binary little-endian with normals, OBJ with vn, STL binary) in WORLD
// coordinates via the Lattice, written atomically (temp file in the same folder, then rename), and
// bounded, validating readers for the same formats (used by tests and tools).
#pragma once

#include <filesystem>

#include "liveset/grid/lattice.hpp"
#include "liveset/mesh/mesh.hpp"

namespace liveset {

enum class MeshFormat { ply, obj, stl };

// Format from the file extension (.ply, .obj, .stl, case-insensitive); std::invalid_argument otherwise.
MeshFormat mesh_format_for_path(const std::filesystem::path& path);

// Writes an index-space mesh in world coordinates: positions through lattice.to_world, normals
// through lattice.direction_to_world. The file appears complete or not at all. Throws
// std::runtime_error naming the path on any I/O failure.
void write_mesh(const std::filesystem::path& path, MeshView mesh, const Lattice& lattice, MeshFormat format);
void write_mesh(const std::filesystem::path& path, MeshView mesh, const Lattice& lattice);  // format by extension

// Readers return the stored (world) coordinates. They reject malformed or truncated files, counts
// that do not fit the file, out-of-range indices and non-triangle faces (except OBJ polygons, which
// are fan-triangulated) with std::runtime_error naming the path. STL gives 3 vertices per triangle
// with the facet normal; OBJ vertex i is the i-th `v` with the first normal it is used with (a `v`
// used with several normals is split into extra vertices appended at the end).
Mesh read_ply(const std::filesystem::path& path);
Mesh read_obj(const std::filesystem::path& path);
Mesh read_stl(const std::filesystem::path& path);
Mesh read_mesh(const std::filesystem::path& path);  // format by extension

}  // namespace liveset
