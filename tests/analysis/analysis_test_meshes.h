#pragma once
// Analytic meshes with known geodesics and curvature, for the mesh-analysis tests.

#include <cmath>
#include <map>
#include <utility>

#include "mesh/tri_mesh.h"

namespace orthoface::testing {

// Icosphere of `radius` centred at the origin, `levels` subdivisions (12, 42, 162, 642, 2562,
// 10242 ... vertices), outward (counter-clockwise) triangles.
inline mesh::TriMesh icosphere(int levels, double radius) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  mesh::TriMesh m;
  m.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      m.vertices.push_back(0.5 * (m.vertices[a] + m.vertices[b]));
      return mid[key] = static_cast<int>(m.vertices.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& f : m.triangles) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = std::move(next);
  }
  for (auto& v : m.vertices) v = v.normalized() * radius;
  return m;
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
