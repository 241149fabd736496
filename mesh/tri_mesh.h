#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace orthoface::mesh {

// The triangle mesh that crosses layer boundaries (model, render, sim, app).
// - vertices: millimetres in the head frame (DESIGN.md) unless a loader says otherwise.
// - triangles: vertex indices, counter-clockwise seen from outside (outward normals).
// - uvs: empty, or one per vertex; OpenGL convention, v = 0 at the BOTTOM row of `texture`
//   (image row = (1 - v) * rows). A UV seam duplicates the vertices on it; topology checks weld
//   coincident vertices first (see mesh/topology.h).
// - colors: empty, or one per vertex, RGB in [0, 1].
// - texture: empty, or 8-bit BGR image that `uvs` index into.
struct TriMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Eigen::Vector2d> uvs;
  std::vector<Eigen::Vector3d> colors;
  cv::Mat texture;
};

// Throws std::invalid_argument, prefixed with `what`, when the mesh has no triangles, a
// non-finite vertex, a triangle index out of range or repeated within a triangle, or uvs /
// colors whose size differs from vertices, or a texture that is not 8-bit BGR.
void check_mesh(const TriMesh& mesh, const std::string& what);

}  // namespace orthoface::mesh
