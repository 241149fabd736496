// The jaw of a simulated head opened: the moving sim head talks (SimCameraOptions::mouth_mm).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/head.h"
#include "sim/head_surface.h"

namespace orthoface::sim {
namespace {

const Eigen::Vector3d& landmark(const Head& head, const std::string& name) {
  const auto it = head.landmarks.find(name);
  if (it == head.landmarks.end())
    throw std::invalid_argument("open_mouth: the head has no '" + name + "' landmark");
  return it->second;
}

// How much of the jaw's turn a point of the closed head follows: all of the lower lip and jaw
// below the lips' line, nothing above it; in front of the ears; fading down the neck (its base
// stays).
struct Jaw {
  double stomion, menton;
  Eigen::Vector3d hinge;
  double weight(const Eigen::Vector3d& p) const {
    return detail::smoothstep(stomion + 0.5, stomion - 1.0, p.y()) *
           detail::smoothstep(hinge.z() - 25, hinge.z() - 5, p.z()) *
           (1 - detail::smoothstep(menton - 5, menton - 45, p.y()));
  }
  // p turned down and back about the hinge (an axis along x) by `angle`.
  Eigen::Vector3d turned(const Eigen::Vector3d& p, double angle) const {
    const double y = p.y() - hinge.y(), z = p.z() - hinge.z();
    const double c = std::cos(angle), s = std::sin(angle);
    return {p.x(), hinge.y() + c * y - s * z, hinge.z() + s * y + c * z};
  }
};

// Paints, in `texture`, the texels of the triangles of `closed` whose vertices the jaw moves
// apart (weights across 0.5) at the mouth: those whose place in the closed head lies within
// gap_fraction / 2 of the band's height from the lips' line (less toward the corners, none
// beyond them), as the mouth's dark inside.
void paint_mouth_inside(const mesh::TriMesh& closed, const std::vector<double>& weight,
                        double stomion, double x_mid, double half_width, double gap_fraction,
                        cv::Mat& texture) {
  const cv::Vec3b inside(20, 18, 45);  // BGR: the dark red of a mouth's inside
  for (const auto& t : closed.triangles) {
    const Eigen::Vector3d& a = closed.vertices[t[0]];
    const Eigen::Vector3d& b = closed.vertices[t[1]];
    const Eigen::Vector3d& c = closed.vertices[t[2]];
    const double w_lo = std::min({weight[t[0]], weight[t[1]], weight[t[2]]});
    const double w_hi = std::max({weight[t[0]], weight[t[1]], weight[t[2]]});
    if (w_hi - w_lo < 0.5) continue;
    if (std::min({std::abs(a.x() - x_mid), std::abs(b.x() - x_mid), std::abs(c.x() - x_mid)}) >
        half_width)
      continue;
    const double y_lo = std::min({a.y(), b.y(), c.y()}), y_hi = std::max({a.y(), b.y(), c.y()});
    const double half = 0.5 * gap_fraction * (y_hi - y_lo);
    // The triangle in texel coordinates (u right, v up).
    const double W = texture.cols, H = texture.rows;
    Eigen::Vector2d q[3];
    for (int k = 0; k < 3; ++k) q[k] = {closed.uvs[t[k]].x() * W, (1 - closed.uvs[t[k]].y()) * H};
    const int x0 = std::max(0, int(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int x1 =
        std::min(texture.cols - 1, int(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int y1 =
        std::min(texture.rows - 1, int(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    const double area =
        (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
    if (std::abs(area) < 1e-12) continue;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d p(x + 0.5, y + 0.5);
        auto edge = [&](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
          return ((v - u).x() * (p - u).y() - (v - u).y() * (p - u).x()) / area;
        };
        const double l0 = edge(q[1], q[2]), l1 = edge(q[2], q[0]), l2 = edge(q[0], q[1]);
        if (l0 < -0.02 || l1 < -0.02 || l2 < -0.02) continue;  // a texel's margin at the edges
        // Rounded toward the corners, as lips part.
        const double x_rest = (l0 * a.x() + l1 * b.x() + l2 * c.x() - x_mid) / half_width;
        const double y_rest = l0 * a.y() + l1 * b.y() + l2 * c.y();
        if (std::abs(y_rest - stomion) <= half * std::sqrt(std::max(0.0, 1 - x_rest * x_rest)))
          texture.at<cv::Vec3b>(y, x) = inside;
      }
  }
}

}  // namespace

Head open_mouth(const Head& head, double open_mm) {
  if (!(open_mm >= 0 && open_mm <= kMaxMouthOpenMm))
    throw std::invalid_argument("open_mouth: the opening must be in [0, " +
                                std::to_string(kMaxMouthOpenMm) + "] mm, got " +
                                std::to_string(open_mm));
  const Eigen::Vector3d& lip_lower = landmark(head, "lip_lower");
  const Eigen::Vector3d& chin = landmark(head, "chin");
  const Eigen::Vector3d &left = landmark(head, "mouth_left"),
                        &right = landmark(head, "mouth_right");
  Jaw jaw;
  jaw.stomion = 0.5 * (landmark(head, "lip_upper").y() + lip_lower.y());
  jaw.menton = landmark(head, "chin_bottom").y();
  jaw.hinge = 0.5 * (landmark(head, "ear_left_tragus") + landmark(head, "ear_right_tragus"));
  if (open_mm == 0) return head;
  // The chin turns about the hinge (down and back) by the angle that lowers it open_mm; the
  // drop grows with the angle over this range for a chin below and in front of the hinge.
  auto drop = [&](const Eigen::Vector3d& p, double a) { return p.y() - jaw.turned(p, a).y(); };
  double lo = 0, hi = 1.2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (drop(chin, mid) < open_mm ? lo : hi) = mid;
  }
  const double angle = 0.5 * (lo + hi);
  Head open = head;
  open.mesh.texture = head.mesh.texture.clone();
  std::vector<double> weight(head.mesh.vertices.size());
  for (size_t i = 0; i < weight.size(); ++i) {
    const Eigen::Vector3d& p = head.mesh.vertices[i];
    weight[i] = jaw.weight(p);
    open.mesh.vertices[i] = p + weight[i] * (jaw.turned(p, angle) - p);
  }
  for (auto& [name, p] : open.landmarks) p += jaw.weight(p) * (jaw.turned(p, angle) - p);
  // The lips part by the lower lip's drop: the stretched band across their line shows that
  // much of the mouth's dark inside.
  if (!head.mesh.texture.empty() && head.mesh.uvs.size() == head.mesh.vertices.size()) {
    const double gap = drop(lip_lower, angle), band = 1.5;  // the band's closed height, about
    paint_mouth_inside(head.mesh, weight, jaw.stomion, 0.5 * (left.x() + right.x()),
                       0.5 * std::abs(left.x() - right.x()), gap / (gap + band), open.mesh.texture);
  }
  return open;
}

}  // namespace orthoface::sim
