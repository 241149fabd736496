#include "render/shapes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::render {
namespace {

cv::Mat procedural_texture(int n) {
  cv::Mat hsv(n, n, CV_8UC3);
  const int cells = 16;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const bool dark = ((r * cells / n) + (c * cells / n)) % 2 == 1;
      hsv.at<cv::Vec3b>(r, c) =
          cv::Vec3b(uchar(180 * c / n), uchar(80 + 150 * r / n), uchar(dark ? 110 : 230));
    }
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return bgr;
}

}  // namespace

mesh::TriMesh uv_ellipsoid(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii, int rings,
                           int segments, int texture_px) {
  if (rings < 2 || segments < 3)
    throw std::invalid_argument("uv_ellipsoid: need rings >= 2 and segments >= 3, got " +
                                std::to_string(rings) + ", " + std::to_string(segments));
  if (!(radii.minCoeff() > 0) || !radii.allFinite() || !centre.allFinite())
    throw std::invalid_argument("uv_ellipsoid: radii must be finite and > 0");
  if (texture_px < 0 || texture_px > 8192)
    throw std::invalid_argument("uv_ellipsoid: texture_px must be in 0..8192");
  mesh::TriMesh m;
  const int cols = segments + 1;  // the seam column is duplicated for the uvs
  for (int i = 0; i <= rings; ++i) {
    const double theta = M_PI * i / rings;
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2 * M_PI * j / segments;
      const Eigen::Vector3d dir(std::sin(theta) * std::sin(phi), std::cos(theta),
                                std::sin(theta) * std::cos(phi));
      m.vertices.push_back(centre + radii.cwiseProduct(dir));
      if (texture_px > 0) m.uvs.emplace_back(double(j) / segments, 1.0 - double(i) / rings);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * cols + j, b = (i + 1) * cols + j, c = a + 1, d = b + 1;
      if (i != 0) m.triangles.push_back({a, b, c});          // a, c coincide at the +y pole
      if (i != rings - 1) m.triangles.push_back({c, b, d});  // b, d coincide at the -y pole
    }
  if (texture_px > 0) m.texture = procedural_texture(texture_px);
  return m;
}

mesh::TriMesh icosphere(int levels, double radius) {
  if (levels < 0 || levels > 8)
    throw std::invalid_argument("icosphere: levels must be 0..8, got " + std::to_string(levels));
  if (!(radius > 0)) throw std::invalid_argument("icosphere: radius must be positive");
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  mesh::TriMesh m;
  m.vertices = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;  // edge -> its midpoint vertex
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      if (const auto it = mid.find(key); it != mid.end()) return it->second;
      m.vertices.push_back(0.5 * (m.vertices[a] + m.vertices[b]));
      return mid[key] = int(m.vertices.size()) - 1;
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

}  // namespace orthoface::render
