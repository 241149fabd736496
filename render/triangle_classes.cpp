#include "render/triangle_classes.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"

namespace orthoface::render {
namespace {

// One source over one triangle.
struct SourceTest {
  bool unoccluded = true;  // the occlusion test passes wherever the source's share can be > 0
  bool whole = false;      // and its share is exactly 1 everywhere (facing, frame, mask)
};

// The source's depth map and mask after a 3 x 3 minimum (the shader reads the texels around
// any point within a pixel of a sample), and the facing cosines of the triangle's corners.
struct SampledSource {
  const capture::CameraModel& camera;
  cv::Mat nearest, mask;
  bool maskable = false;  // texture texels = photo pixels: the mask and frame tests are exact
};

// Samples triangle `t` every half source pixel against the sampled source, each sample's depth
// raised by one step of the sampling grid.
SourceTest source_test(const SampledSource& s, const std::vector<Eigen::Vector3d>& vertices,
                       const std::array<int, 3>& t, const Eigen::Vector3d& cosine,
                       double tolerance_mm) {
  const capture::CameraModel& c = s.camera;
  const bool perspective = c.projection == capture::Projection::Perspective;
  Eigen::Vector3d z;
  Eigen::Vector2d uv[3];
  for (int k = 0; k < 3; ++k) {
    z[k] = capture::depth(c, vertices[t[k]]);
    uv[k] = detail::undistorted_pixel(c, vertices[t[k]]);
  }
  SourceTest r;
  if (cosine.maxCoeff() <= 0) return r;  // faces away: share 0 everywhere
  double longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, (uv[k] - uv[(k + 1) % 3]).norm());
  if (!std::isfinite(longest)) return SourceTest{false, false};
  r.whole = cosine.minCoeff() >= 0.1 && s.maskable;  // smoothstep(0, 0.1, cos) == 1
  const int steps = std::max(1, int(std::ceil(2.0 * longest)));
  const double z_step = (z.maxCoeff() - z.minCoeff()) / steps;
  for (int a = 0; a <= steps; ++a)
    for (int b = 0; a + b <= steps; ++b) {
      const Eigen::Vector3d w(double(a) / steps, double(b) / steps, double(steps - a - b) / steps);
      const double cos_p = w.dot(cosine), z_p = w.dot(z);
      if (cos_p <= 0 || (perspective && !(z_p > 0))) {  // share 0 here
        r.whole = false;
        continue;
      }
      const Eigen::Vector3d p =
          w[0] * vertices[t[0]] + w[1] * vertices[t[1]] + w[2] * vertices[t[2]];
      const Eigen::Vector2d u = detail::undistorted_pixel(c, p);
      const int col = std::clamp(int(std::floor(u.x())), 0, c.width - 1);
      const int row = std::clamp(int(std::floor(u.y())), 0, c.height - 1);
      const double px_mm = (perspective ? z_p : 1.0) / c.fx;
      const double tol = tolerance_mm + 1.5 * px_mm / std::max(cos_p, 0.2);
      if (!(z_p + z_step <= s.nearest.at<float>(row, col) + tol - 1e-3))
        return SourceTest{false, false};
      if (!r.whole) continue;
      const Eigen::Vector2d d = capture::project(c, p);  // the photo position, distorted
      const int dc = int(std::floor(d.x())), dr = int(std::floor(d.y()));
      r.whole = dc >= 1 && dr >= 1 && dc + 1 < c.width && dr + 1 < c.height &&
                (s.mask.empty() || s.mask.at<std::uint8_t>(dr, dc) == 255);
    }
  return r;
}

void check_inputs(const std::vector<Eigen::Vector3d>& vertices,
                  const std::vector<Eigen::Vector3d>& normals,
                  const std::vector<std::array<int, 3>>& triangles,
                  const std::array<TriangleSource, 2>& sources, double tolerance_mm) {
  const std::string what = "triangle facts: ";
  if (normals.size() != vertices.size())
    throw std::invalid_argument(what + "normals has " + std::to_string(normals.size()) +
                                " entries for " + std::to_string(vertices.size()) + " vertices");
  for (const auto& t : triangles)
    for (int v : t)
      if (v < 0 || size_t(v) >= vertices.size())
        throw std::invalid_argument(what + "triangles has vertex index " + std::to_string(v) +
                                    " of " + std::to_string(vertices.size()) + " vertices");
  for (int i = 0; i < 2; ++i) {
    const TriangleSource& s = sources[i];
    const cv::Size size(s.camera.width, s.camera.height);
    const std::string name = what + (i == 0 ? "front" : "side") + " source ";
    if (s.depth_mm.type() != CV_32FC1 || s.depth_mm.size() != size)
      throw std::invalid_argument(name + "depth_mm must be CV_32F of the camera's size " +
                                  std::to_string(size.width) + "x" + std::to_string(size.height));
    if (!s.mask.empty() && (s.mask.type() != CV_8UC1 || s.mask.size() != size))
      throw std::invalid_argument(name + "mask must be empty or CV_8U of the camera's size");
  }
  if (!(tolerance_mm >= 0) || !std::isfinite(tolerance_mm))
    throw std::invalid_argument(what + "visibility_tolerance_mm must be finite and >= 0");
}

}  // namespace

std::vector<TriangleFacts> triangle_facts(const std::vector<Eigen::Vector3d>& vertices,
                                          const std::vector<Eigen::Vector3d>& normals,
                                          const std::vector<std::array<int, 3>>& triangles,
                                          const std::array<TriangleSource, 2>& sources,
                                          double visibility_tolerance_mm) {
  check_inputs(vertices, normals, triangles, sources, visibility_tolerance_mm);
  std::vector<SampledSource> sampled;
  sampled.reserve(2);
  for (const TriangleSource& s : sources) {
    SampledSource& q = sampled.emplace_back(SampledSource{s.camera, {}, {}, s.full_resolution});
    cv::erode(s.depth_mm, q.nearest, cv::Mat());  // 3x3 minimum
    if (!s.mask.empty()) cv::erode(s.mask, q.mask, cv::Mat());
  }
  std::vector<std::array<double, 2>> facing(vertices.size());  // per vertex, per source
  for (size_t v = 0; v < vertices.size(); ++v)
    for (int i = 0; i < 2; ++i)
      facing[v][i] = detail::facing(sources[i].camera, vertices[v], normals[v]);
  std::vector<TriangleFacts> facts;
  facts.reserve(triangles.size());
  for (const auto& t : triangles) {
    SourceTest s[2];
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3d cosine(facing[t[0]][i], facing[t[1]][i], facing[t[2]][i]);
      s[i] = source_test(sampled[i], vertices, t, cosine, visibility_tolerance_mm);
    }
    TriangleFacts f;
    f.whole = {s[0].whole, s[1].whole};
    f.unoccluded = s[0].unoccluded && s[1].unoccluded;
    for (int k = 0; k < 3; ++k) {
      const double c0 = facing[t[k]][0], c1 = facing[t[k]][1];
      f.lead[0] = std::min(f.lead[0], c0 - c1), f.lead[1] = std::min(f.lead[1], c1 - c0);
      f.max_cos[0] = std::max(f.max_cos[0], c0), f.max_cos[1] = std::max(f.max_cos[1], c1);
    }
    facts.push_back(f);
  }
  return facts;
}

// The blend's share of the front photo is 1 (0) where cos0 - cos1 + bias >= feather (<= -),
// and these cosines are interpolated linearly: the corners decide for the whole triangle.
TriangleOrder order_triangles(const std::vector<std::array<int, 3>>& triangles,
                              const std::vector<TriangleFacts>& facts, const ClassRule& rule) {
  if (facts.size() != triangles.size())
    throw std::invalid_argument("order triangles: facts has " + std::to_string(facts.size()) +
                                " entries for " + std::to_string(triangles.size()) + " triangles");
  if (!(rule.feather > 0) || !std::isfinite(rule.feather) || !std::isfinite(rule.bias) ||
      !(rule.hull_share >= 0 && rule.hull_share <= 1))
    throw std::invalid_argument(
        "order triangles: rule needs a positive finite feather, a finite bias and a hull share "
        "in 0..1");
  std::array<std::vector<std::array<int, 3>>, 4> by_class;
  const double hull_bias = rule.bias * rule.hull_share;
  for (size_t k = 0; k < triangles.size(); ++k) {
    const TriangleFacts& f = facts[k];
    // The bias over the triangle: the face's, the hull's, or between them where it spans both.
    int hull_corners = 0;
    for (int v : triangles[k]) hull_corners += rule.face_vertices >= 0 && v >= rule.face_vertices;
    const double lo = hull_corners == 0   ? rule.bias
                      : hull_corners == 3 ? hull_bias
                                          : std::min(rule.bias, hull_bias),
                 hi = hull_corners == 0   ? rule.bias
                      : hull_corners == 3 ? hull_bias
                                          : std::max(rule.bias, hull_bias);
    // Pick / view: the leading photo alone when it covers the triangle fully. Weighted: a photo
    // alone only where the other faces away.
    const bool front_only =
        f.whole[0] && (rule.weighted ? f.max_cos[1] <= 0 : f.lead[0] + lo >= rule.feather);
    const bool side_only =
        f.whole[1] && (rule.weighted ? f.max_cos[0] <= 0 : f.lead[1] - hi >= rule.feather);
    const auto c = front_only     ? TriangleClass::kFrontOnly
                   : side_only    ? TriangleClass::kSideOnly
                   : f.unoccluded ? TriangleClass::kUnoccluded
                                  : TriangleClass::kTested;
    by_class[int(c)].push_back(triangles[k]);
  }
  TriangleOrder order;
  order.triangles.reserve(triangles.size());
  for (int k = 0; k < 4; ++k) {
    order.count[k] = int(by_class[k].size());
    order.triangles.insert(order.triangles.end(), by_class[k].begin(), by_class[k].end());
  }
  return order;
}

}  // namespace orthoface::render
