#pragma once
// Analytic meshes with known geodesics and curvature, for the mesh-analysis tests.

#include <cmath>
#include <map>
#include <utility>

#include "mesh/tri_mesh.h"
#include "render/shapes.h"

namespace orthoface::testing {

// Icosphere of `radius` centred at the origin, `levels` subdivisions (render/shapes.h).
inline mesh::TriMesh icosphere(int levels, double radius) {
  return render::icosphere(levels, radius);
}

// Open cylinder of `radius` around +y, `height` tall, n_around x n_up quads split in two.
inline mesh::TriMesh cylinder(double radius, double height, int n_around, int n_up) {
  mesh::TriMesh m;
  for (int j = 0; j <= n_up; ++j)
    for (int i = 0; i < n_around; ++i) {
      const double a = 2.0 * M_PI * i / n_around;
      m.vertices.emplace_back(radius * std::sin(a), height * j / n_up, radius * std::cos(a));
    }
  for (int j = 0; j < n_up; ++j)
    for (int i = 0; i < n_around; ++i) {
      const int a = j * n_around + i, b = j * n_around + (i + 1) % n_around;
      const int c = a + n_around, d = b + n_around;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  return m;
}

// Flat square grid in the z = 0 plane, n x n quads of side `step`, normals +z.
inline mesh::TriMesh plane_grid(int n, double step) {
  mesh::TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.emplace_back(i * step, j * step, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  return m;
}

// Great-circle distance on a sphere of `radius` between two points on it.
inline double great_circle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return radius * std::acos(c);
}

}  // namespace orthoface::testing
