#pragma once

// Internal to mesh/mesh_io*.cpp: the per-format readers and writers behind read_mesh /
// write_mesh, and the helpers they share.

#include <string>

#include <opencv2/core.hpp>

#include "mesh/mesh_io.h"

namespace orthoface::mesh::io {

// Throws std::runtime_error("<path>: <message>").
[[noreturn]] void fail(const std::string& path, const std::string& message);

// Whole file as bytes; throws (naming the file) when it is missing or unreadable.
std::string read_bytes(const std::string& path);

// BGR 8-bit image at image_path (relative paths resolved next to mesh_path); throws naming both.
cv::Mat load_texture(const std::string& image_path, const std::string& mesh_path);

// Final checks on a freshly read mesh: triangles present, finite values, indices in range,
// at least one triangle of non-zero area. Throws fail(path, ...).
void validate_read(const TriMesh& mesh, const std::string& path);

TriMesh read_obj(const std::string& path, const MeshReadOptions& options);
TriMesh read_off(const std::string& path);
TriMesh read_ply(const std::string& path, const MeshReadOptions& options);
TriMesh read_gltf(const std::string& path, const MeshReadOptions& options);

void write_obj(const TriMesh& mesh, const std::string& path);
void write_off(const TriMesh& mesh, const std::string& path);
void write_ply(const TriMesh& mesh, const std::string& path, bool binary);

}  // namespace orthoface::mesh::io
