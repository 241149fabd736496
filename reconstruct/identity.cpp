#include "reconstruct/identity.h"

#include <algorithm>

#include "reconstruct/views.h"
#include "vision/face_descriptor.h"

namespace orthoface::reconstruct {
namespace {

// The square around the model's landmarks as `camera` sees them, 1.2 x their larger extent;
// empty when too few project.
cv::Rect2d face_box(const Reconstruction& r, const capture::CameraModel& camera) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  int n = 0;
  for (const char* name :
       {"eye_left_outer", "eye_right_outer", "eye_left_inner", "eye_right_inner", "brow_left_outer",
        "brow_right_outer", "mouth_left", "mouth_right", "nose_tip", "chin_bottom"}) {
    const auto it = r.landmarks.find(name);
    if (it == r.landmarks.end()) continue;
    const Eigen::Vector2d p = capture::project(camera, it->second);
    if (!p.allFinite()) continue;
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
    ++n;
  }
  if (n < 6) return {};
  const double side = 1.2 * std::max(x1 - x0, y1 - y0);
  return {(x0 + x1) / 2 - side / 2, (y0 + y1) / 2 - side / 2, side, side};
}

}  // namespace

std::optional<double> front_to_view_face_distance(const Reconstruction& r) {
  const vision::FaceLandmarker68* landmarker = vision::shared_landmarker();
  const vision::FaceDescriber* describer = vision::shared_describer();
  if (!landmarker || !describer || r.front.empty() || r.side.empty() || r.landmarks.empty())
    return std::nullopt;
  const cv::Rect2d front_box = face_box(r, r.photo_rig.front);
  if (front_box.empty()) return std::nullopt;
  const auto front_face = landmarker->detect_in(r.front, front_box, 4);
  if (vision::face_descriptor_crop(front_face.points, r.front.size()).empty()) return std::nullopt;
  const vision::FaceDescriptor front = describer->describe(r.front, front_face.points);
  // As `orthoface render` draws a view, but blended per pixel and aligned by the raw flow: the
  // banded blend and the round-trip check on the flow both hide a wrong pair's misfit, where
  // the raw flow drags the other person's features across the face (docs/input_check.md).
  ViewOptions o;
  o.synthesis.blend_bands = 1;
  o.synthesis.float_round_trip = false;
  // As the views the limit was set on (docs/input_check.md).
  o.synthesis.ramp_narrowing = 64;
  o.synthesis.view_gain = 2;
  o.synthesis.camera_gain = 2;
  o.synthesis.camera_power = 64;
  o.twist_neck = false;  // the limit was set on views whose neck turns with the head
  ViewRenderer views(r, o);
  double sum = 0;
  int n = 0;
  for (const double deg : kIdentityViewsDeg) {
    const double yaw = deg * capture::photographed_side_sign(r.photo_rig);
    const cv::Mat view = views.image(yaw, 0);
    const cv::Rect2d box = face_box(r, views.camera(yaw, 0));
    if (box.empty()) continue;
    const auto face = landmarker->detect_in(view, box, 4);
    if (vision::face_descriptor_crop(face.points, view.size()).empty()) continue;
    sum += vision::descriptor_distance(front, describer->describe(view, face.points));
    ++n;
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

}  // namespace orthoface::reconstruct
