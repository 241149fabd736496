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
  const double yaw = 45 * capture::photographed_side_sign(r.photo_rig);
  // As `orthoface render` draws a view, but blended per pixel: the banded blend hides part of a
  // wrong pair's misfit (the right pairs' largest distance rose 0.67 -> 0.68, docs/input_check.md).
  ViewOptions per_pixel;
  per_pixel.synthesis.blend_bands = 1;
  ViewRenderer views(r, per_pixel);
  const cv::Mat view = views.image(yaw, 0);
  const cv::Rect2d front_box = face_box(r, r.photo_rig.front);
  const cv::Rect2d view_box = face_box(r, views.camera(yaw, 0));
  if (front_box.empty() || view_box.empty()) return std::nullopt;
  const auto front_face = landmarker->detect_in(r.front, front_box, 4);
  const auto view_face = landmarker->detect_in(view, view_box, 4);
  if (vision::face_descriptor_crop(front_face.points, r.front.size()).empty() ||
      vision::face_descriptor_crop(view_face.points, view.size()).empty())
    return std::nullopt;
  return vision::descriptor_distance(describer->describe(r.front, front_face.points),
                                     describer->describe(view, view_face.points));
}

}  // namespace orthoface::reconstruct
