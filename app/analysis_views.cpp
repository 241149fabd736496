#include "app/analysis_views.h"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "render/renderer.h"

namespace orthoface::app {

capture::CameraModel view_camera(const mesh::TriMesh& mesh, const Eigen::Vector3d& view_dir,
                                 const Eigen::Vector3d& up, int size) {
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  const Eigen::Vector3d f = view_dir.normalized();
  Eigen::Vector3d u = (up - up.dot(f) * f);
  if (u.norm() < 1e-9) u = f.unitOrthogonal();
  u.normalize();
  const Eigen::Vector3d right = f.cross(u);  // camera +x; camera +y is -u (image down)
  Eigen::Matrix3d rot;
  rot.row(0) = right.transpose();
  rot.row(1) = (-u).transpose();
  rot.row(2) = f.transpose();
  const double diag = box.diagonal().norm();
  capture::CameraModel cam;
  cam.projection = capture::Projection::Orthographic;
  cam.width = cam.height = size;
  double extent = 1e-9;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector3d q = rot * (v - box.center());
    extent = std::max({extent, std::abs(q.x()), std::abs(q.y())});
  }
  cam.fx = cam.fy = 0.46 * size / extent;
  cam.cx = cam.cy = 0.5 * size;
  cam.cam_from_head.linear() = rot;
  cam.cam_from_head.translation() = -rot * box.center() + Eigen::Vector3d(0, 0, 2.0 * diag);
  return cam;
}

cv::Mat render_view(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                    const std::vector<Marker>& markers) {
  render::RenderOptions ro;
  ro.background = cv::Scalar(255, 255, 255);
  ro.light.direction_head = capture::view_direction(camera);
  ro.light.ambient = 0.35;
  ro.light.diffuse = 0.65;
  ro.cull_back_faces = false;  // scans may have inconsistent orientation
  mesh::TriMesh plain;
  plain.vertices = mesh.vertices;
  plain.triangles = mesh.triangles;
  plain.colors = mesh.colors;
  const render::RenderResult r = render::render_once(plain, camera, ro);
  cv::Mat img = r.image.clone();
  for (const Marker& m : markers) {
    const Eigen::Vector2d px = capture::project(camera, m.position);
    if (!px.allFinite()) continue;
    const int c = int(px.x()), row = int(px.y());
    if (c < 0 || row < 0 || c >= img.cols || row >= img.rows) continue;
    // Only markers on the visible surface (depth test against the rendered depth).
    const float zbuf = r.depth_mm.at<float>(row, c);
    const double z = capture::depth(camera, m.position);
    const double tol = 0.02 * (2.0 * camera.width / camera.fx);
    if (std::isfinite(zbuf) && z > zbuf + tol) continue;
    cv::circle(img, {c, row}, 5, m.bgr, cv::FILLED, cv::LINE_AA);
    cv::circle(img, {c, row}, 5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    if (!m.label.empty())
      cv::putText(img, m.label, {c + 6, row - 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
                  cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  return img;
}

Eigen::Vector3d heat_rgb(double t) {
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0);
  if (t < 0.5) return {0.0, 2.0 * t, 1.0 - 2.0 * t};
  return {2.0 * t - 1.0, 2.0 - 2.0 * t, 0.0};
}

Eigen::Vector3d label_rgb(int i) {
  // Golden-angle hues, alternating brightness, so neighbouring labels differ.
  const double h = std::fmod(i * 137.508, 360.0) / 60.0;
  const double v = i % 2 ? 0.95 : 0.75, s = 0.7;
  const double c = v * s, x = c * (1 - std::abs(std::fmod(h, 2.0) - 1)), m = v - c;
  Eigen::Vector3d rgb;
  switch (int(h)) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  return rgb + Eigen::Vector3d::Constant(m);
}

}  // namespace orthoface::app
