#pragma once

// Internal to sim/: the analytic head surface behind make_head (not a public contract).

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "sim/head.h"

namespace orthoface::sim::detail {

inline constexpr double kEarTilt = 0.2;  // radians; the top of the ear leans back

// Heights (y, mm) and positions of the features, derived from HeadParams.
struct HeadAnchors {
  double y_top, y_bottom;  // crown, bottom of the neck
  double y_dome;           // where the cranial dome starts closing
  double y_nasion, y_eye, y_brow, y_hair;
  double y_tip, y_sub, y_mouth, y_menton, y_chin_start;
  double x_eye_left, x_eye_right;  // eye centres (x)
  double y_eye_left, y_eye_right;  // eye centres (y); differ only with asymmetry
  double x_mid;                    // nose / mouth midline shift (asymmetry)
  double y_ear_c, z_ear_c;         // ear centre on the side
  double ear_rz, ear_ry;           // ear half sizes (z, y)
  double y_tragus, z_tragus;
};

// A closed surface given by stacked horizontal sections: for a height y in [y_top, y_bottom]
// and azimuth theta (0 = +z, pi/2 = +x), the point is (r sin theta, y, r cos theta) with
// r = radius(theta, y) > 0 (0 only at the crown). Sections are star-shaped around the y axis, so
// the surface cannot fold or self-intersect.
class HeadSurface {
 public:
  explicit HeadSurface(const HeadParams& params);

  double radius(double theta, double y) const;
  Eigen::Vector3d point(double theta, double y) const;
  // Ear coordinates at (theta, y) on the side: (r, w, v) with r < 1 inside the ear outline,
  // w across the ear (+ toward the face), v along it (+ up), both in units of the half sizes.
  Eigen::Vector3d ear_coords(double theta, double y) const;
  // 0..1: how much of the ear is at (theta, y) (texture, landmarks).
  double ear_weight(double theta, double y) const;

  const HeadParams& params() const { return p_; }
  const HeadAnchors& anchors() const { return a_; }

 private:
  double base_radius(double theta, double y) const;
  double face_bumps(double x, double y, double front) const;
  double nose_bump(double x, double y) const;
  double mouth_bumps(double x, double y) const;
  double ear_bump(double z, double y, double side) const;

  HeadParams p_;
  HeadAnchors a_;
  Eigen::Vector4d section(double y) const;  // half width, front, back, front exponent

  std::vector<Eigen::Vector4d> table_;  // section() sampled every kTableStep mm from y_bottom
  double nose_tip_amp_ = 0;             // nose profile height at the tip over the face
  bool with_nose_ = true;
};

// The (u, t) parametrization used for the mesh grid and the texture: u in [0, 1] goes around
// (seam at the back, u = 0.5 the midline of the face, denser at the face), t in [0, 1] from
// the crown (t = 0) to the bottom of the neck (t = 1), spaced by weighted profile arc length.
class HeadParametrization {
 public:
  explicit HeadParametrization(const HeadSurface& surface);
  static double theta(double u);
  static double u_of_theta(double theta);
  double y(double t) const;
  double t_of_y(double y) const;

 private:
  std::vector<double> ys_, ts_;  // descending y, ascending t
};

// Texture (BGR, size x size) of the head in (u, v = 1 - t) coordinates: skin, hair, brows,
// eyes, lips, nostrils, ears. Deterministic for given params.
cv::Mat head_texture(const HeadSurface& surface, const HeadParametrization& param, int size);

// Landmarks as surface parameters (u, t), and the heights of the profile landmarks (the mesh
// puts a ring on each, so they are vertices).
struct LandmarkParams {
  std::map<std::string, Eigen::Vector2d> ut;
  std::vector<double> key_y;
};
LandmarkParams landmark_params(const HeadSurface& surface, const HeadParametrization& param);

// Brow centre line at s in [0, 1] (0 = inner end, 1 = outer end) of side +1 (left, +x) or -1:
// (x, y, thickness) in mm, on the front projection. Shared by the texture and the landmarks.
Eigen::Vector3d brow_point(const HeadSurface& surface, int side, double s);

// Smooth 0..1 step between e0 and e1 (cubic Hermite).
double smoothstep(double e0, double e1, double x);

}  // namespace orthoface::sim::detail
