// Scenes whose true views are known, shared by the texture inheritance tests: the source
// photos and the truth are renders of the same textured mesh.
#pragma once

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "render/shapes.h"

namespace orthoface::render::testing {

using capture::CameraModel;

struct Scene {
  mesh::TriMesh textured, bare;
  capture::RigCalibration rig;
  cv::Mat front, side;
};

inline mesh::TriMesh without_texture(mesh::TriMesh m) {
  m.uvs.clear();
  m.texture = cv::Mat();
  m.colors.clear();
  return m;
}

inline Scene make_scene(const mesh::TriMesh& textured, const capture::RigCalibration& rig) {
  Scene s{textured, without_texture(textured), rig, {}, {}};
  Renderer r;
  s.front = r.render(textured, rig.front).image;
  s.side = r.render(textured, rig.side).image;
  return s;
}

inline Scene ellipsoid_scene() {
  return make_scene(uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 48, 96, 512),
                    capture::ideal_rig(640, 480, 2.0));
}

inline CameraModel view(const CameraModel& intrinsics, double yaw_deg, double pitch_deg = 0,
                        double distance = 1000) {
  return capture::camera_at(intrinsics, yaw_deg * M_PI / 180, pitch_deg * M_PI / 180, distance);
}

// Head point seen at pixel (c, r) with depth z (mm) by camera `cam`.
inline Eigen::Vector3d unproject(const CameraModel& cam, int c, int r, double z) {
  double x = (c + 0.5 - cam.cx) / cam.fx, y = (r + 0.5 - cam.cy) / cam.fy;
  if (cam.projection == capture::Projection::Perspective) x *= z, y *= z;
  return cam.cam_from_head.inverse() * Eigen::Vector3d(x, y, z);
}

// Pixels of a view rendered with source_weights whose colour is the front photo's alone.
inline cv::Mat only_from_front(const SynthesisResult& r) {
  cv::Mat front_weight;
  cv::extractChannel(r.weights, front_weight, 0);
  return (front_weight == 255) & r.view.mask;
}

}  // namespace orthoface::render::testing
