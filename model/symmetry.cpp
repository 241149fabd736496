#include "model/symmetry.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include "vision/landmarks.h"

namespace orthoface::model {

std::optional<Eigen::Vector4d> mid_sagittal_plane(
    const std::map<std::string, Eigen::Vector3d>& landmarks) {
  for (const auto& [name, p] : landmarks)
    if (!p.allFinite())
      throw std::invalid_argument("mid_sagittal_plane: landmark '" + name + "' is not finite");
  Eigen::Vector3d across = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> on_plane;
  int pairs = 0;
  for (const auto& [name, p] : landmarks) {
    if (!vision::is_landmark_name(name)) continue;
    const std::string twin = vision::mirrored_name(name);
    if (twin == name) {
      on_plane.push_back(p);
      continue;
    }
    if (name.find("_left") == std::string::npos) continue;  // each pair once, from its left
    const auto right = landmarks.find(twin);
    if (right == landmarks.end()) continue;
    const Eigen::Vector3d d = p - right->second;
    if (d.norm() < 1e-9) continue;
    across += d.normalized();
    on_plane.push_back(0.5 * (p + right->second));
    ++pairs;
  }
  if (pairs < 2 || across.norm() < 1e-9) return std::nullopt;
  const Eigen::Vector3d n = across.normalized();
  double d = 0;
  for (const auto& p : on_plane) d += n.dot(p);
  d /= double(on_plane.size());
  return Eigen::Vector4d(n.x(), n.y(), n.z(), d);
}

Eigen::Matrix4d reflection(const Eigen::Vector4d& plane) {
  const Eigen::Vector3d n = plane.head<3>();
  if (!plane.allFinite() || std::abs(n.norm() - 1) > 1e-6)
    throw std::invalid_argument("reflection: the plane's normal must be finite and of unit length");
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() -= 2 * n * n.transpose();
  m.topRightCorner<3, 1>() = 2 * plane.w() * n;  // p' = p - 2 (n . p - d) n
  return m;
}

}  // namespace orthoface::model
