#include "sim/face_mask.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "sim/rig.h"

namespace orthoface::sim {
namespace {

constexpr double kBelowChinMm = 5;
constexpr double kInFrontOfEarsMm = 15;

const Eigen::Vector3d& landmark(const Head& head, const char* name) {
  const auto it = head.landmarks.find(name);
  if (it == head.landmarks.end())
    throw std::invalid_argument("face_vertices: head '" + head.name + "' has no landmark " + name);
  return it->second;
}

}  // namespace

bool has_face_landmarks(const Head& head) {
  for (const char* n : {"forehead_top", "chin_bottom", "ear_left_tragus", "ear_right_tragus"})
    if (!head.landmarks.count(n)) return false;
  return true;
}

std::vector<bool> face_vertices(const Head& head) {
  const double y_top = landmark(head, "forehead_top").y();
  const double y_bottom = landmark(head, "chin_bottom").y() - kBelowChinMm;
  const double z_ears =
      std::max(landmark(head, "ear_left_tragus").z(), landmark(head, "ear_right_tragus").z());
  std::vector<bool> in(head.mesh.vertices.size());
  for (size_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3d& v = head.mesh.vertices[i];
    in[i] = v.y() >= y_bottom && v.y() <= y_top && v.z() >= z_ears + kInFrontOfEarsMm;
  }
  return in;
}

cv::Mat face_mask(const Head& head, const capture::CameraModel& camera,
                  render::Renderer& renderer) {
  const std::vector<bool> in = face_vertices(head);
  // The head drawn in two flat colours: white face, black rest; unlit, no texture.
  mesh::TriMesh m;
  m.vertices = head.mesh.vertices;
  m.triangles = head.mesh.triangles;
  m.colors.resize(in.size());
  for (size_t i = 0; i < in.size(); ++i) m.colors[i] = Eigen::Vector3d::Constant(in[i] ? 1.0 : 0.0);
  const render::RenderResult r = renderer.render(m, camera);
  cv::Mat grey;
  cv::extractChannel(r.image, grey, 1);
  cv::Mat mask = (grey > 127) & r.mask;
  return mask;
}

capture::CameraModel true_view_camera(const RigOptions& options, double yaw_rad, double pitch_rad) {
  const capture::RigCalibration rig = nominal_rig(options);
  if (!std::isfinite(yaw_rad) || !std::isfinite(pitch_rad))
    throw std::invalid_argument("true_view: yaw and pitch must be finite");
  const double distance = options.kind == RigKind::Ideal ? 1000.0 : options.distance_mm;
  return capture::camera_at(rig.front, yaw_rad, pitch_rad, distance);
}

cv::Mat landmark_hull_mask(const Head& head, const capture::CameraModel& camera, cv::Size size) {
  std::vector<cv::Point> corners, hull;
  for (const auto& [name, x] : head.landmarks) {
    if (name.rfind("ear", 0) == 0 || name == "forehead_top") continue;
    const Eigen::Vector2d p = capture::project(camera, x);
    corners.emplace_back(cvRound(p.x()), cvRound(p.y()));
  }
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  if (corners.size() < 3) return mask;
  cv::convexHull(corners, hull);
  cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  return mask;
}

}  // namespace orthoface::sim
