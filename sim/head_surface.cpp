#include "sim/head_surface.h"

#include <algorithm>
#include <cmath>

namespace orthoface::sim::detail {

namespace {

constexpr double kUnionPower = 10;   // p-norm union of head and neck sections (smooth max)
constexpr double kTableStep = 0.25;  // mm between tabulated section keyframes

double gauss2(double dx, double sx, double dy, double sy) {
  return std::exp(-0.5 * (dx * dx / (sx * sx) + dy * dy / (sy * sy)));
}

double sigmoid(double x) { return 1.0 / (1.0 + std::exp(-x)); }

// log-sum-exp smooth maximum, at most k * log 2 above max(a, b).
double soft_max(double a, double b, double k) {
  const double m = std::max(a, b);
  return m + k * std::log(std::exp((a - m) / k) + std::exp((b - m) / k));
}

// Radius of a superellipse-like section: semi-axes a (x), f (+z), b (-z), exponent n.
double section_radius(double theta, double a, double f, double b, double n) {
  const double s = std::abs(std::sin(theta)), c = std::cos(theta);
  const double depth = c >= 0 ? f : b;
  const double sum = std::pow(s / a, n) + std::pow(std::abs(c) / depth, n);
  return std::pow(sum, -1.0 / n);
}

// Ray from the axis at azimuth theta against the ellipse (x/ax)^2 + ((z-zc)/az)^2 = 1.
double ellipse_radius(double theta, double ax, double az, double zc) {
  const double s = std::sin(theta), c = std::cos(theta);
  const double qa = s * s / (ax * ax) + c * c / (az * az);
  const double qb = -2.0 * c * zc / (az * az);
  const double qc = zc * zc / (az * az) - 1.0;
  return (-qb + std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);
}

// Cubic Hermite through (ys[k], vs[k]) with descending ys and Catmull-Rom tangents; constant
// outside the range.
double hermite(const std::vector<double>& ys, const std::vector<double>& vs, double y) {
  const size_t n = ys.size();
  if (y >= ys.front()) return vs.front();
  if (y <= ys.back()) return vs.back();
  size_t k = 0;
  while (k + 2 < n && y < ys[k + 1]) ++k;
  auto slope = [&](size_t i) {
    if (i == 0 || i + 1 == n) return 0.0;
    return (vs[i + 1] - vs[i - 1]) / (ys[i + 1] - ys[i - 1]);
  };
  const double h = ys[k + 1] - ys[k];  // negative
  const double t = (y - ys[k]) / h;
  const double t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * vs[k] + (t3 - 2 * t2 + t) * h * slope(k) +
         (-2 * t3 + 3 * t2) * vs[k + 1] + (t3 - t2) * h * slope(k + 1);
}

}  // namespace

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

HeadSurface::HeadSurface(const HeadParams& p) : p_(p) {
  HeadAnchors& a = a_;
  a.y_nasion = 14;
  a.y_eye = a.y_nasion - 5;
  a.y_brow = a.y_eye + 17;
  a.y_dome = a.y_nasion + 32;
  a.y_sub = a.y_nasion - p.nose_length;
  a.y_tip = a.y_sub + 0.32 * p.nose_length;
  a.y_mouth = a.y_sub - 0.4 * p.nose_length;
  a.y_menton = a.y_mouth - p.chin_height;
  a.y_chin_start = a.y_menton + 12;
  a.y_top = a.y_menton + p.head_height;
  a.y_hair = a.y_nasion + 0.55 * (a.y_top - a.y_nasion);
  a.y_bottom = a.y_menton - p.neck_length;
  a.x_mid = 3.0 * p.asymmetry;
  a.x_eye_left = p.eye_spacing / 2;
  a.x_eye_right = -p.eye_spacing / 2;
  a.y_eye_left = a.y_eye + 2.0 * p.asymmetry;
  a.y_eye_right = a.y_eye;
  a.ear_ry = p.ear_size / 2;
  a.ear_rz = 0.3 * p.ear_size;
  a.y_ear_c = p.ear_height + 0.1 * p.ear_size;
  a.z_ear_c = -a.ear_rz + 1.5;
  a.y_tragus = p.ear_height;
  a.z_tragus = 1.0;

  // Section keyframes from the dome down to the chin: half width, front, back, front exponent.
  const double hw = p.head_width / 2, hd = p.head_depth / 2, jw = p.jaw_width / 2;
  std::vector<double> key_y = {a.y_dome, a.y_brow,  a.y_eye,        0.0,           a.y_tip,
                               a.y_sub,  a.y_mouth, a.y_mouth - 12, a.y_chin_start};
  const std::vector<Eigen::Vector4d> key = {{hw, hd - 3, hd, 2.2},
                                            {hw - 1.5, hd - 5.5, hd - 1, 2.3},
                                            {hw - 3.5, hd - 9, hd - 4, 2.45},
                                            {hw - 6, hd - 10, hd - 10, 2.45},
                                            {hw - 9, hd - 10.5, hd - 24, 2.3},
                                            {std::max(jw + 6, hw - 14), hd - 10.5, hd - 40, 2.1},
                                            {jw + 3, hd - 10.5, 35, 1.9},
                                            {jw, hd - 11, 15, 1.8},
                                            {0.32 * p.jaw_width, hd - 12, 5, 2.0}};
  // Keyframes must descend; a very short face could break that, so keep them apart.
  for (size_t k = 1; k < key_y.size(); ++k) key_y[k] = std::min(key_y[k], key_y[k - 1] - 1.0);
  const int n = static_cast<int>((a.y_top - a.y_bottom) / kTableStep) + 2;
  table_.resize(n);
  std::vector<double> col(key_y.size());
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 4; ++c) {
      for (size_t k = 0; k < key.size(); ++k) col[k] = key[k][c];
      table_[i][c] = hermite(key_y, col, a.y_bottom + i * kTableStep);
    }
  // Nose tip height over the face so that tip minus subnasale (z) = nose_projection.
  with_nose_ = false;
  const double r_sub = radius(0, a.y_sub), r_tip = radius(0, a.y_tip);
  with_nose_ = true;
  nose_tip_amp_ = p.nose_projection + 2.5 + r_sub - r_tip;
}

Eigen::Vector4d HeadSurface::section(double y) const {
  const double f = std::clamp((y - a_.y_bottom) / kTableStep, 0.0, table_.size() - 1.001);
  const int i = static_cast<int>(f);
  return table_[i] + (f - i) * (table_[i + 1] - table_[i]);
}

double HeadSurface::base_radius(double theta, double y) const {
  const HeadAnchors& a = a_;
  double head = 0;
  if (y < a.y_top && y > a.y_menton - 8) {
    const Eigen::Vector4d afbn = section(y);
    double scale = 1;
    if (y > a.y_dome) {
      const double q = (y - a.y_dome) / (a.y_top - a.y_dome);
      scale = std::sqrt(std::max(0.0, 1 - q * q));
    } else if (y < a.y_chin_start) {
      const double q = (a.y_chin_start - y) / (a.y_chin_start - (a.y_menton - 8));
      scale = std::sqrt(std::max(0.0, 1 - q * q));
    }
    head = scale * section_radius(theta, afbn[0], afbn[1], afbn[2], afbn[3]);
  }
  // The neck: an elliptic cylinder behind the chin, closing as a dome inside the head.
  double neck = 0;
  const double neck_top = a.y_tip + 10;
  if (y < neck_top) {
    double scale = 1;
    if (y > a.y_mouth) {
      const double q = (y - a.y_mouth) / (neck_top - a.y_mouth);
      scale = std::sqrt(std::max(0.0, 1 - q * q));
    }
    // The neck leans forward a little toward its base.
    const double w = p_.neck_width;
    const double zc = -(0.1 * w + 6) + 0.12 * std::max(0.0, a.y_menton - y);
    if (scale > 0) neck = ellipse_radius(theta, scale * w / 2, scale * 0.46 * w, scale * zc);
  }
  return std::pow(std::pow(head, kUnionPower) + std::pow(neck, kUnionPower), 1.0 / kUnionPower);
}

double HeadSurface::nose_bump(double x, double y) const {
  const HeadAnchors& a = a_;
  const double xm = x - a.x_mid;
  const double yn = a.y_nasion, yt = a.y_tip, ys = a.y_sub;
  const double amp_nasion = 1.5, amp_sub = 2.5;
  const double amp_tip = nose_tip_amp_;
  double prof = 0, q = 0;
  if (y >= yt) {
    q = std::clamp((yn - y) / (yn - yt), 0.0, 1.0);
    double dorsum = amp_nasion + (amp_tip - 2.0 - amp_nasion) * q;
    if (y > yn) dorsum = amp_nasion * std::exp(-0.5 * std::pow((y - yn) / 6.0, 2));
    const double rt = (y - yt) / 9.0;
    const double bulb = rt < 1 ? amp_tip * std::sqrt(1 - rt * rt) : 0.0;
    prof = soft_max(dorsum, bulb, 0.8);
  } else if (y > ys) {
    q = 1;
    const double r = (yt - y) / (yt - ys);
    prof = amp_sub + (amp_tip - amp_sub) * std::pow(std::max(0.0, 1 - std::pow(r, 2.2)), 0.6);
  } else {
    q = 1;
    prof = amp_sub * std::exp(-0.5 * std::pow((ys - y) / 2.0, 2));
  }
  const double w = 6.0 + (0.27 * p_.nose_width - 6.0) * q;
  double nose = prof * std::exp(-0.5 * xm * xm / (w * w));
  // Alar wings, their outer edge at nose_width / 2, and the nostril dents under them.
  for (double side : {-1.0, 1.0}) {
    const double dx = (xm - side * (p_.nose_width / 2 - 7)) / 7.5;
    const double dy = (y - (ys + 5)) / 6.5;
    nose += 0.42 * amp_tip * std::exp(-std::pow(dx * dx + dy * dy, 1.5));
    nose -= 1.5 * gauss2(xm - side * (p_.nose_width / 2 - 9.5), 3, y - (ys + 2), 2);
  }
  return nose;
}

double HeadSurface::mouth_bumps(double x, double y) const {
  const HeadAnchors& a = a_;
  const double xm = x - a.x_mid, F = p_.lip_fullness;
  const double hm = p_.mouth_width / 2;
  const double mask = std::exp(-std::pow(std::abs(xm) / hm, 4));
  const double mask_low = std::exp(-std::pow(std::abs(1.1 * xm) / hm, 4));
  double r = 5.0 * std::exp(-0.5 * xm * xm / (24.0 * 24.0)) *
             smoothstep(a.y_mouth - 22, a.y_mouth - 10, y) *
             (1 - smoothstep(a.y_sub - 2, a.y_sub + 6, y));
  r += 3.5 * F * mask * std::exp(-0.5 * std::pow((y - (a.y_mouth + 3.5 * F)) / (2.8 * F), 2));
  r += 4.0 * F * mask_low * std::exp(-0.5 * std::pow((y - (a.y_mouth - 4.5 * F)) / (3.3 * F), 2));
  r -= 2.0 * mask * std::exp(-0.5 * std::pow((y - a.y_mouth) / 1.3, 2));
  r -= 2.5 * gauss2(xm, 15, y - (a.y_mouth - 13 * F), 3.5);
  r += (4.0 + p_.chin_projection) * gauss2(xm, 13, y - (a.y_menton + 13), 7);
  return r;
}

double HeadSurface::face_bumps(double x, double y, double front) const {
  if (front <= 0) return 0;
  const HeadAnchors& a = a_;
  double r = 0.6 * p_.brow_ridge * gauss2(x, 11, y - (a.y_nasion + 9), 7);
  const double xs[2] = {a.x_eye_right, a.x_eye_left}, ys[2] = {a.y_eye_right, a.y_eye_left};
  for (int k = 0; k < 2; ++k) {
    const double side = k == 0 ? -1 : 1, xe = xs[k], ye = ys[k];
    const double dx = x - xe, dy = y - ye, rr = std::hypot(dx, dy);
    r -= 8.0 * gauss2(dx, 15, dy - 1, 10);              // socket
    r += 6.5 * std::exp(-0.5 * rr * rr / 64.0);         // eyeball
    r += 1.2 * std::exp(-0.5 * rr * rr / (4.5 * 4.5));  // cornea
    r += 1.3 * gauss2(dx, 11, dy - 6, 2.5);             // upper lid
    r += p_.brow_ridge * gauss2(x - side * (std::abs(xe) - 1), 17, y - (ye + 17), 6);
    r += 3.0 * gauss2(x - side * (std::abs(xe) + 20), 12, y - (ye - 16), 8);  // cheekbone
    r += (7.0 * p_.cheek_fullness - 1.5) *
         gauss2(x - side * (std::abs(xe) + 12), 14, y - (a.y_tip - 6), 15);  // cheek
  }
  if (with_nose_) r += nose_bump(x, y);
  r += mouth_bumps(x, y);
  return front * r;
}

double HeadSurface::ear_bump(double z, double y, double side) const {
  const HeadAnchors& a = a_;
  const double ez = z - a.z_ear_c, ey = y - a.y_ear_c;
  const double v = -ez * std::sin(kEarTilt) + ey * std::cos(kEarTilt);
  const double w = ez * std::cos(kEarTilt) + ey * std::sin(kEarTilt);
  const double r = std::hypot(w / a.ear_rz, v / a.ear_ry);
  const double P = 1.3 * p_.ear_protrusion;
  const double inside = sigmoid((1 - r) / 0.05);
  double e = P * (0.55 + 0.45 * std::exp(-std::pow((r - 0.82) / 0.13, 2))) * inside *
             (0.8 - 0.2 * std::clamp(w / a.ear_rz, -1.0, 1.0));
  e -= 0.4 * P * gauss2(w - 0.25 * a.ear_rz, 0.3 * a.ear_rz, v + 0.1 * a.ear_ry, 0.25 * a.ear_ry);
  e += 0.35 * P * gauss2(z - a.z_tragus, 3, y - a.y_tragus, 4);
  (void)side;
  return std::max(e, 0.0);
}

Eigen::Vector3d HeadSurface::ear_coords(double theta, double y) const {
  const HeadAnchors& a = a_;
  const double z = base_radius(theta, y) * std::cos(theta);
  const double ez = z - a.z_ear_c, ey = y - a.y_ear_c;
  const double v = -ez * std::sin(kEarTilt) + ey * std::cos(kEarTilt);
  const double w = ez * std::cos(kEarTilt) + ey * std::sin(kEarTilt);
  return {std::hypot(w / a.ear_rz, v / a.ear_ry), w / a.ear_rz, v / a.ear_ry};
}

double HeadSurface::ear_weight(double theta, double y) const {
  return sigmoid((1 - ear_coords(theta, y)[0]) / 0.05) *
         smoothstep(0.55, 0.8, std::abs(std::sin(theta)));
}

double HeadSurface::radius(double theta, double y) const {
  const double r0 = base_radius(theta, y);
  const double s = std::sin(theta), c = std::cos(theta);
  double r = r0;
  const double front = smoothstep(0.25, 0.55, c);
  if (front > 0) r += face_bumps(r0 * s, y, front);
  const double side = smoothstep(0.55, 0.8, std::abs(s));
  if (side > 0) r += side * ear_bump(r0 * c, y, s > 0 ? 1 : -1);
  return std::max(r, 0.0);
}

Eigen::Vector3d HeadSurface::point(double theta, double y) const {
  const double r = radius(theta, y);
  return {r * std::sin(theta), y, r * std::cos(theta)};
}

}  // namespace orthoface::sim::detail
