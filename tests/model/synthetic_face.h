#pragma once
// A synthetic face for the model tests: the base mesh under a known anisotropic transform,
// observed through the ideal rig, so every 3D answer is known.
#include <Eigen/Core>

#include "capture/camera_model.h"
#include "model/base_mesh.h"
#include "vision/observation.h"

namespace orthoface::testing {

struct SyntheticFace {
  model::BaseMesh truth;                // base mesh moved by p -> scale .* p + offset
  vision::FaceObservation observation;  // ideal-rig observation of `truth`
  capture::RigCalibration rig;
};

inline SyntheticFace synthetic_face(const Eigen::Vector3d& scale, const Eigen::Vector3d& offset,
                                    double nose_extra_mm = 0.0) {
  SyntheticFace s;
  s.truth = model::base_mesh();
  for (auto& v : s.truth.mesh.vertices) {
    const double bump =
        nose_extra_mm * std::exp(-(v.x() * v.x() + (v.y() + 10) * (v.y() + 10)) / 200.0);
    v = scale.cwiseProduct(v) + offset + Eigen::Vector3d(0, 0, bump);
  }
  s.rig = capture::ideal_rig(640, 480, 1.6);
  auto px = [&](const capture::CameraModel& c, int v) {
    const Eigen::Vector2d p = capture::project(c, s.truth.mesh.vertices[v]);
    return cv::Point2d(p.x(), p.y());
  };
  auto& o = s.observation;
  o.front.width = o.side.width = 640;
  o.front.height = o.side.height = 480;
  for (const auto& ids : s.truth.slices) o.front.boundary.push_back(px(s.rig.front, ids.front()));
  for (const auto& ids : s.truth.slices) o.front.boundary.push_back(px(s.rig.front, ids.back()));
  for (size_t sl = 0; sl < s.truth.slices.size(); ++sl)
    o.side.boundary.push_back(px(s.rig.side, s.truth.centre(static_cast<int>(sl))));
  o.front.boundary_confidence = o.side.boundary_confidence = 1.0;
  const Eigen::Vector2d c = capture::project(s.rig.front, offset);
  o.centre_x_px = c.x();
  o.centre_y_px = c.y();
  for (const auto& [name, v] : s.truth.features) {
    o.front.features[name] = {px(s.rig.front, v), 1.0, "synthetic", false};
    if (name.find("_right") == std::string::npos)
      o.side.features[name] = {px(s.rig.side, v), 1.0, "synthetic", false};
  }
  return s;
}

}  // namespace orthoface::testing
