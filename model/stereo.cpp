#include "model/stereo.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>

#include "vision/landmarks.h"

namespace orthoface::model {
namespace {

struct Ray {
  Eigen::Vector3d origin, direction;  // head frame, direction unit
};

// The viewing ray of a pixel, head frame. Orthographic: a parallel ray through the pixel's
// point on the image plane; perspective: through the camera centre, distortion removed.
Ray pixel_ray(const capture::CameraModel& cam, const Eigen::Vector2d& px) {
  const Eigen::Isometry3d head_from_cam = cam.cam_from_head.inverse();
  const Eigen::Matrix3d r = head_from_cam.linear();
  if (cam.projection == capture::Projection::Orthographic) {
    const Eigen::Vector3d p_cam((px.x() - cam.cx) / cam.fx, (px.y() - cam.cy) / cam.fy, 0.0);
    return {head_from_cam * p_cam, r.col(2).normalized()};
  }
  double xn = (px.x() - cam.cx) / cam.fx, yn = (px.y() - cam.cy) / cam.fy;
  if (!cam.distortion.empty()) {
    const cv::Matx33d k(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    std::vector<cv::Point2d> in{{px.x(), px.y()}}, out;
    cv::undistortPoints(in, out, k, cam.distortion);
    xn = out[0].x;
    yn = out[0].y;
  }
  return {head_from_cam.translation(), (r * Eigen::Vector3d(xn, yn, 1.0)).normalized()};
}

// Where a ray meets the plane n . p = d (the ray's own origin when parallel).
Eigen::Vector3d on_plane(const Ray& ray, const Eigen::Vector3d& n, double d) {
  const double den = n.dot(ray.direction);
  if (std::abs(den) < 1e-12) return ray.origin;
  return ray.origin + ray.direction * ((d - n.dot(ray.origin)) / den);
}

void require_finite(const std::vector<cv::Point2d>& pts, const std::string& what) {
  for (size_t i = 0; i < pts.size(); ++i)
    if (!std::isfinite(pts[i].x) || !std::isfinite(pts[i].y))
      throw std::invalid_argument("stereo_match: " + what + " point " + std::to_string(i) +
                                  " is not finite");
}

// Extreme value (max of sign * value) over the polyline segments that cross height y.
// x of segment ab at height y, or nullopt when ab does not reach y.
std::optional<double> segment_at(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double y) {
  if ((a.y() - y) * (b.y() - y) > 0) return std::nullopt;
  const double t = std::abs(b.y() - a.y()) < 1e-12 ? 0.5 : (y - a.y()) / (b.y() - a.y());
  return a.x() + t * (b.x() - a.x());
}

void keep_extreme(std::optional<double> v, int sign, std::optional<double>& best) {
  if (v && (!best || sign * *v > sign * *best)) best = v;
}

std::optional<double> extreme_at(const std::vector<Eigen::Vector2d>& curve, double y, int sign) {
  std::optional<double> best;
  for (size_t i = 0; i + 1 < curve.size(); ++i)
    keep_extreme(segment_at(curve[i], curve[i + 1], y), sign, best);
  return best;
}

double confidence_of(const vision::Feature2d& f) { return std::clamp(f.confidence, 0.0, 1.0); }

void check_observation(const vision::FaceObservation& obs) {
  require_finite(obs.front.boundary, "front boundary");
  require_finite(obs.side.boundary, "side boundary");
  for (const auto* view : {&obs.front, &obs.side})
    for (const auto& [name, f] : view->features)
      if (!std::isfinite(f.px.x) || !std::isfinite(f.px.y))
        throw std::invalid_argument("stereo_match: feature '" + name + "' is not finite");
  if (!std::isfinite(obs.centre_x_px) || !std::isfinite(obs.centre_y_px) ||
      !std::isfinite(obs.roll_rad))
    throw std::invalid_argument("stereo_match: centre line is not finite");
  if (obs.front.boundary.size() < 3)
    throw std::invalid_argument("cannot reconstruct: the front view has no silhouette (" +
                                std::to_string(obs.front.boundary.size()) + " boundary points)");
  if (obs.side.boundary.size() < 3)
    throw std::invalid_argument("cannot reconstruct: the side view has no profile (" +
                                std::to_string(obs.side.boundary.size()) + " boundary points)");
}

// The side view in the head frame's convention (face toward the image left): when the camera
// stood on the subject's right, mirror the columns and swap left / right names.
vision::ViewObservation side_facing_left(const vision::FaceObservation& obs) {
  if (obs.side_faces_left) return obs.side;
  vision::ViewObservation s = obs.side;
  for (cv::Point2d& p : s.boundary) p.x = s.width - p.x;
  s.features.clear();
  for (auto [name, f] : obs.side.features) {
    f.px.x = obs.side.width - f.px.x;
    s.features[vision::is_landmark_name(name) ? vision::mirrored_name(name) : name] = f;
  }
  return s;
}

void set_centre_line(const vision::FaceObservation& obs, const capture::CameraModel& front,
                     StereoData& d) {
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  const Eigen::Vector2d p0(obs.centre_x_px, obs.centre_y_px);
  const Eigen::Vector2d p1 = p0 + Eigen::Vector2d(std::tan(obs.roll_rad), 1.0) * 100.0;
  const Eigen::Vector3d a = on_plane(pixel_ray(front, p0), n, 0.0);
  const Eigen::Vector3d b = on_plane(pixel_ray(front, p1), n, 0.0);
  d.centre_point = a.head<2>();
  d.centre_direction = (b - a).head<2>().normalized();
  if (obs.front.width > 0 && (obs.centre_x_px <= 0 || obs.centre_x_px >= obs.front.width)) {
    double sum = 0;
    for (const Eigen::Vector2d& p : d.silhouette) sum += p.x();
    d.centre_point = {sum / d.silhouette.size(), 0.0};
    d.centre_direction = Eigen::Vector2d::UnitY();
    d.warnings.push_back("centre line outside the front image: using the silhouette's mean x");
  }
}

void set_height_range(StereoData& d, double min_overlap) {
  auto range = [](const std::vector<Eigen::Vector2d>& c) {
    double lo = c[0].y(), hi = c[0].y();
    for (const auto& p : c) lo = std::min(lo, p.y()), hi = std::max(hi, p.y());
    return std::pair{lo, hi};
  };
  const auto [s_lo, s_hi] = range(d.silhouette);
  const auto [p_lo, p_hi] = range(d.profile);
  d.y_bottom = std::max(s_lo, p_lo);
  d.y_top = std::min(s_hi, p_hi);
  const double overlap = std::max(0.0, d.y_top - d.y_bottom);
  if (s_hi - s_lo <= 0 || overlap < min_overlap * (s_hi - s_lo))
    throw std::invalid_argument("inconsistent heights between views: the side profile spans y " +
                                std::to_string(p_lo) + ".." + std::to_string(p_hi) +
                                " mm, the front silhouette y " + std::to_string(s_lo) + ".." +
                                std::to_string(s_hi) + " mm");
}

double reprojection_px(const capture::RigCalibration& rig, const Eigen::Vector3d& p,
                       const Eigen::Vector2d& front_px, const Eigen::Vector2d* side_px) {
  double e = (capture::project(rig.front, p) - front_px).norm();
  if (side_px) e = std::max(e, (capture::project(rig.side, p) - *side_px).norm());
  return e;
}

// 3D position of one front feature, with the side view, the profile or symmetry for depth.
std::optional<StereoPoint> match_feature(const std::string& name, const vision::Feature2d& f,
                                         const vision::FaceObservation& obs,
                                         const vision::ViewObservation& side,
                                         const capture::RigCalibration& rig, StereoData& d) {
  const Eigen::Vector2d fpx(f.px.x, f.px.y);
  const Ray fray = pixel_ray(rig.front, fpx);
  StereoPoint sp;
  sp.confidence = confidence_of(f);
  const bool midline = vision::mirrored_name(name) == name;
  const auto same = side.features.find(name);
  const auto mirror = side.features.find(vision::mirrored_name(name));
  if (same != side.features.end()) {
    const Eigen::Vector2d spx(same->second.px.x, same->second.px.y);
    sp.head_mm = triangulate(rig, fpx, spx);
    sp.confidence = std::min(sp.confidence, confidence_of(same->second));
    sp.mismatch_px = reprojection_px(rig, sp.head_mm, fpx, &spx);
  } else if (!midline && mirror != side.features.end()) {
    // Symmetry (seed 004 §4): the subject's right feature has the depth of its left twin.
    const Eigen::Vector2d spx(mirror->second.px.x, mirror->second.px.y);
    const auto twin = obs.front.features.find(mirror->first);
    const Eigen::Vector2d tpx = twin != obs.front.features.end()
                                    ? Eigen::Vector2d(twin->second.px.x, twin->second.px.y)
                                    : fpx;
    const Eigen::Vector3d t = triangulate(rig, tpx, spx);
    sp.head_mm = on_plane(fray, Eigen::Vector3d::UnitZ(), t.z());
    sp.confidence = std::min(sp.confidence, confidence_of(mirror->second));
    sp.mismatch_px = reprojection_px(rig, t, tpx, &spx);
  } else {
    sp.head_mm = on_plane(fray, Eigen::Vector3d::UnitZ(), 0.0);
    const auto z = midline ? profile_z_at(d, sp.head_mm.y()) : std::nullopt;
    if (z)
      sp.head_mm = on_plane(fray, Eigen::Vector3d::UnitZ(), *z);
    else
      sp.has_depth = false;
  }
  return sp;
}

}  // namespace

void StereoOptions::check() const {
  if (!(warn_mismatch_px > 0) || !(reject_mismatch_px >= warn_mismatch_px))
    throw std::invalid_argument("StereoOptions: need 0 < warn_mismatch_px <= reject_mismatch_px");
  if (!(min_height_overlap >= 0 && min_height_overlap <= 1))
    throw std::invalid_argument("StereoOptions: min_height_overlap must be in [0, 1]");
}

Eigen::Vector3d point_at_depth(const capture::CameraModel& camera, const Eigen::Vector2d& px,
                               double z_mm) {
  return on_plane(pixel_ray(camera, px), Eigen::Vector3d::UnitZ(), z_mm);
}

Eigen::Vector3d triangulate(const capture::RigCalibration& rig, const Eigen::Vector2d& front_px,
                            const Eigen::Vector2d& side_px) {
  // Midpoint of the two rays' closest points. For the ideal rig of seed 004 (front ray along
  // -z, side ray along -x, equal scale) this is exactly eq. 1: x from the front column, z from
  // the side column, y the (mean) shared row.
  const Ray a = pixel_ray(rig.front, front_px), b = pixel_ray(rig.side, side_px);
  const Eigen::Vector3d w0 = a.origin - b.origin;
  const double bb = a.direction.dot(b.direction);
  const double d = a.direction.dot(w0), e = b.direction.dot(w0);
  const double den = 1.0 - bb * bb;
  if (den < 1e-9) throw std::invalid_argument("triangulate: the two viewing rays are parallel");
  const double s = (bb * e - d) / den, t = (e - bb * d) / den;
  return 0.5 * ((a.origin + s * a.direction) + (b.origin + t * b.direction));
}

std::optional<double> silhouette_x_at(const StereoData& data, double y, int sign) {
  const double c = centre_x_at(data, y);
  const std::vector<Eigen::Vector2d>& s = data.silhouette;
  std::optional<double> best;  // over the segments with both ends on the requested side
  for (size_t i = 0; i + 1 < s.size(); ++i) {
    if ((s[i].y() - y) * (s[i + 1].y() - y) > 0) continue;  // cheapest test first
    if (sign * (s[i].x() - c) > 0 && sign * (s[i + 1].x() - c) > 0)
      keep_extreme(segment_at(s[i], s[i + 1], y), sign, best);
  }
  return best;
}

std::optional<double> profile_z_at(const StereoData& data, double y) {
  return extreme_at(data.profile, y, +1);
}

double centre_x_at(const StereoData& data, double y) {
  const Eigen::Vector2d& d = data.centre_direction;
  if (std::abs(d.y()) < 1e-9) return data.centre_point.x();
  return data.centre_point.x() + d.x() / d.y() * (y - data.centre_point.y());
}

}  // namespace orthoface::model

namespace orthoface::model {

StereoData stereo_match(const vision::FaceObservation& obs, const capture::RigCalibration& rig,
                        const StereoOptions& options) {
  options.check();
  check_observation(obs);
  const vision::ViewObservation side = side_facing_left(obs);
  StereoData d;
  for (const cv::Point2d& p : obs.front.boundary)
    d.silhouette.push_back(
        on_plane(pixel_ray(rig.front, {p.x, p.y}), Eigen::Vector3d::UnitZ(), 0.0).head<2>());
  for (const cv::Point2d& p : side.boundary) {
    const Eigen::Vector3d q =
        on_plane(pixel_ray(rig.side, {p.x, p.y}), Eigen::Vector3d::UnitX(), 0.0);
    d.profile.emplace_back(q.z(), q.y());
  }
  set_centre_line(obs, rig.front, d);
  set_height_range(d, options.min_height_overlap);
  for (const auto& [name, f] : obs.front.features) {
    if (!vision::is_landmark_name(name)) {
      d.warnings.push_back("feature '" + name + "' is not a landmark name: ignored");
      continue;
    }
    auto sp = match_feature(name, f, obs, side, rig, d);
    if (sp->mismatch_px > options.reject_mismatch_px) {
      d.warnings.push_back("feature '" + name + "': views disagree by " +
                           std::to_string(static_cast<int>(sp->mismatch_px)) + " px, dropped");
      continue;
    }
    if (sp->mismatch_px > options.warn_mismatch_px)
      d.warnings.push_back("feature '" + name + "': views disagree by " +
                           std::to_string(static_cast<int>(sp->mismatch_px)) + " px");
    d.features[name] = *sp;
  }
  return d;
}

}  // namespace orthoface::model
