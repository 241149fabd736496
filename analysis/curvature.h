#pragma once

#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::analysis {

// Per-vertex curvature, indexed like mesh.vertices (1 / mesh units). Sign: positive where the
// surface bends away from its outward normal (a sphere with outward triangles has k = +1/r).
struct Curvature {
  std::vector<double> k1, k2;               // principal curvatures, k1 >= k2
  std::vector<Eigen::Vector3d> dir1, dir2;  // principal directions (unit, tangent)
  std::vector<Eigen::Vector3d> normals;     // unit vertex normals used
};

// Principal curvatures by Rusinkiewicz 2004 (per-face second fundamental tensor fitted to the
// normal differences along the edges, moved into each vertex frame and averaged with Voronoi
// corner areas), as seed 003 §5.1 uses. Degenerate triangles are skipped; a vertex with no
// usable triangle gets 0. Throws std::invalid_argument on a malformed mesh (mesh::check_mesh).
Curvature principal_curvatures(const mesh::TriMesh& mesh);

// The four metrics of seed 003 §5.2 from k1 >= k2 (eqs. 11-14).
double mean_curvature(double k1, double k2);      // (k1 + k2) / 2
double gaussian_curvature(double k1, double k2);  // k1 k2
// 1/2 - atan((k1 + k2) / (k1 - k2)) / pi in [0, 1]: 0 = convex cap, 1/2 = saddle or plane
// (k1 = k2 = 0), 1 = concave cup. Throws std::invalid_argument if k1 < k2.
double shape_index(double k1, double k2);
double curvedness(double k1, double k2);  // sqrt((k1^2 + k2^2) / 2)

// Weighted mean of `values` at `vertex` over itself and its 1- and 2-ring (vertices at edge
// distance exactly 1 and 2), weights w0 / w1 / w2 (seed 003 eq. 15-16: 100 / 10 / 1).
// Throws std::invalid_argument on size mismatch, vertex out of range or negative weights.
double ring_average(const std::vector<std::vector<int>>& neighbors,
                    const std::vector<double>& values, int vertex, double w0 = 100.0,
                    double w1 = 10.0, double w2 = 1.0);

}  // namespace orthoface::analysis
