// Landmarks of the simulated head, found on the analytic surface and expressed as (u, t)
// surface parameters; make_head maps them onto the mesh.
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "sim/head_surface.h"

namespace orthoface::sim::detail {

namespace {

constexpr double kPi = std::numbers::pi;

// Azimuth where the front half of the section at height y reaches x (front projection).
double front_theta(const HeadSurface& s, double x, double y) {
  const double dir = x >= 0 ? 1.0 : -1.0;
  auto fx = [&](double th) { return s.radius(th, y) * std::sin(th) - x; };
  double lo = 0, step = 0.004 * dir;
  for (double th = step; std::abs(th) < kPi / 2; th += step) {
    if (fx(th) * dir >= 0) {
      double a = lo, b = th;
      for (int k = 0; k < 50; ++k) {
        const double m = 0.5 * (a + b);
        (fx(m) * dir < 0 ? a : b) = m;
      }
      return 0.5 * (a + b);
    }
    lo = th;
  }
  throw std::logic_error("front_theta: x = " + std::to_string(x) + " is off the face");
}

// Azimuth on side `dir` (+1 left) where the section at height y reaches z (side projection).
double side_theta(const HeadSurface& s, double z, double y, double dir) {
  auto fz = [&](double th) { return s.radius(th, y) * std::cos(th) - z; };  // decreasing
  double lo = 0.2 * dir;
  const double step = 0.004 * dir;
  for (double th = lo + step; std::abs(th) < kPi - 0.2; th += step) {
    if (fz(th) <= 0) {
      double a = lo, b = th;
      for (int k = 0; k < 50; ++k) {
        const double m = 0.5 * (a + b);
        (fz(m) > 0 ? a : b) = m;
      }
      return 0.5 * (a + b);
    }
    lo = th;
  }
  throw std::logic_error("side_theta: z = " + std::to_string(z) + " is off the side");
}

struct Profile {
  double theta = 0;
  std::vector<double> y, z;  // descending y
  // Index of the sample maximising score(y, z) with y in [y_lo, y_hi].
  size_t best(double y_lo, double y_hi, const std::function<double(double, double)>& score) const {
    size_t arg = 0;
    double top = -1e300;
    for (size_t k = 0; k < y.size(); ++k)
      if (y[k] >= y_lo && y[k] <= y_hi && score(y[k], z[k]) > top) {
        top = score(y[k], z[k]);
        arg = k;
      }
    return arg;
  }
  // True when z at sample k is the highest within +-win samples (both inside the profile).
  bool peak_at(int k, int win) const {
    for (int j = k - win; j <= k + win; ++j)
      if (z[j] > z[k]) return false;
    return true;
  }
};

// Upper lip (labrale superius): the first peak of z (the highest over +-2 mm) going up from the
// mouth line, below the subnasale. A plain maximum over that range took its top, the foot of
// the columella, on heads whose upper lip is retruded under a forward-sloping philtrum; that
// maximum stays the fallback when no peak is found.
size_t upper_lip(const Profile& p, double y_mouth, double y_top) {
  const double step = p.y[0] - p.y[1];
  const int win = std::max(1, int(std::lround(2.0 / step)));
  for (int k = int(p.y.size()) - 1 - win; k >= win; --k) {  // from the bottom up
    if (p.y[k] < y_mouth) continue;
    if (p.y[k] > y_top) break;
    if (p.peak_at(k, win)) return size_t(k);
  }
  return p.best(y_mouth, y_top, [](double, double z) { return z; });
}

// Pogonion: the most projecting point of the chin prominence, i.e. the lowest local maximum
// of z between the lower lip and the menton that stands 0.3 mm over the labiomental fold above
// it. A retruded chin without such a bump has its most anterior chin point where the profile
// turns vertical: the flattest slope within 25 mm above the menton. (A plain maximum of z up to
// just under the lower lip took the top of that range on retruded chins, whose profile keeps
// rising toward the lip.)
size_t pogonion(const Profile& p, double y_menton, double y_lip_lower) {
  const double step = p.y[0] - p.y[1], y_top = y_lip_lower - 2;
  const int win = std::max(1, int(std::lround(3.0 / step))), fold = int(std::lround(15.0 / step));
  const int n = int(p.y.size());
  for (int k = n - 1 - win; k >= win; --k) {  // from the bottom up
    if (p.y[k] < y_menton - 2) continue;
    if (p.y[k] > y_top) break;
    if (!p.peak_at(k, win)) continue;
    double z_fold = p.z[k];
    for (int j = k - 1; j >= std::max(0, k - fold) && p.y[j] <= y_top; --j)
      z_fold = std::min(z_fold, p.z[j]);
    if (p.z[k] - z_fold >= 0.3) return size_t(k);
  }
  size_t best = 0;
  double flat = 1e300;
  for (int k = 1; k + 1 < n; ++k) {
    if (p.y[k] < y_menton || p.y[k] > std::min(y_top, y_menton + 25)) continue;
    const double slope = std::abs((p.z[k - 1] - p.z[k + 1]) / (p.y[k - 1] - p.y[k + 1]));
    if (slope < flat) flat = slope, best = size_t(k);
  }
  return best;
}

// Midline profile landmarks (DESIGN: side view): heights on the profile through the nose.
std::map<std::string, double> profile_heights(const HeadSurface& s, double theta) {
  const HeadAnchors& a = s.anchors();
  Profile p;
  p.theta = theta;
  for (double y = a.y_brow + 10; y > a.y_menton - 25; y -= 0.05) {
    p.y.push_back(y);
    p.z.push_back(s.radius(theta, y) * std::cos(theta));
  }
  auto zmax = [](double, double z) { return z; };
  std::map<std::string, double> h;
  const size_t tip = p.best(a.y_sub, a.y_nasion, zmax);
  const size_t bridge = p.best(p.y[tip] + 8, a.y_nasion + 9, [](double, double z) { return -z; });
  const size_t lu = upper_lip(p, a.y_mouth, a.y_sub - 1);
  const size_t ll = p.best(a.y_mouth - 14, a.y_mouth, zmax);
  const size_t chin = pogonion(p, a.y_menton, p.y[ll]);
  // Subnasale: where the columella (the nose's underside, running back at over 2 mm per mm of
  // height) turns down into the upper lip: going down from the tip, the first point after the
  // columella whose slope |dz/dy| is under 1 (slopes over +-0.5 mm). The deepest point
  // behind the tip-to-lip chord slid down a forward-sloping philtrum when the lip is low; it
  // stays the fallback.
  const int half = std::max(1, int(std::lround(0.5 / (p.y[0] - p.y[1]))));
  size_t sub = lu;
  bool columella = false;
  for (size_t k = tip + half; k + half < lu; ++k) {
    const double slope =
        std::abs((p.z[k - half] - p.z[k + half]) / (p.y[k - half] - p.y[k + half]));
    if (slope > 2)
      columella = true;
    else if (columella) {
      sub = k;
      break;
    }
  }
  if (sub == lu) {
    const Eigen::Vector2d T(p.z[tip], p.y[tip]), L(p.z[lu], p.y[lu]);
    Eigen::Vector2d nrm(-(L - T).y(), (L - T).x());
    if (nrm.x() > 0) nrm = -nrm;  // toward the inside of the face (smaller z)
    nrm.normalize();
    sub = p.best(p.y[lu], p.y[tip],
                 [&](double y, double z) { return (Eigen::Vector2d(z, y) - T).dot(nrm); });
  }
  // Chin bottom (gnathion): the chin point projecting furthest 45 degrees below forward;
  // steeper directions would pick the throat, which leans forward under the chin, and so would
  // a search reaching far below the menton (it starts 2 mm under it).
  const size_t cb = p.best(a.y_menton - 2, p.y[chin], [](double y, double z) { return z - y; });
  h["nose_tip"] = p.y[tip];
  h["nose_bridge"] = p.y[bridge];
  h["lip_upper"] = p.y[lu];
  h["lip_lower"] = p.y[ll];
  h["chin"] = p.y[chin];
  h["subnasale"] = p.y[sub];
  h["chin_bottom"] = p.y[cb];
  return h;
}

// Widest point of the face at height y in front of the ear (z >= tragus + 12), side dir.
double cheek_theta(const HeadSurface& s, double y, double dir) {
  const double z_min = s.anchors().z_tragus + 12;
  double best = 0, best_x = -1;
  for (double th = 0.3; th < kPi / 2; th += 0.002) {
    const double r = s.radius(dir * th, y);
    if (r * std::cos(th) < z_min) break;
    if (r * std::sin(th) > best_x) {
      best_x = r * std::sin(th);
      best = dir * th;
    }
  }
  return best;
}

}  // namespace

Eigen::Vector3d brow_point(const HeadSurface& surface, int side, double s) {
  const HeadAnchors& a = surface.anchors();
  const HeadParams& p = surface.params();
  const double xe = side > 0 ? a.x_eye_left : a.x_eye_right;
  const double ye = side > 0 ? a.y_eye_left : a.y_eye_right;
  const double x_in = std::abs(xe) - p.eye_width / 2 - 1,
               x_out = std::abs(xe) + p.eye_width / 2 + 5;
  const double q = (s - 0.6) / 0.6;
  return {side * (x_in + s * (x_out - x_in)), ye + 13 + 5 * (1 - q * q), 5.5 - 2.5 * s};
}

LandmarkParams landmark_params(const HeadSurface& s, const HeadParametrization& param) {
  const HeadAnchors& a = s.anchors();
  const HeadParams& p = s.params();
  LandmarkParams out;
  auto put = [&](const std::string& name, double theta, double y) {
    out.ut[name] = {HeadParametrization::u_of_theta(theta), param.t_of_y(y)};
  };
  const double theta_mid = a.x_mid == 0 ? 0.0 : front_theta(s, a.x_mid, a.y_tip);
  for (const auto& [name, y] : profile_heights(s, theta_mid)) {
    put(name, theta_mid, y);
    out.key_y.push_back(y);
  }
  put("forehead_top", theta_mid, a.y_hair);
  out.key_y.push_back(a.y_eye);
  out.key_y.push_back(a.y_mouth);
  out.key_y.push_back(a.y_tragus);  // the origin lies between the tragi exactly
  for (int side : {1, -1}) {
    const std::string lr = side > 0 ? "left" : "right";
    const double xe = side > 0 ? a.x_eye_left : a.x_eye_right;
    const double ye = side > 0 ? a.y_eye_left : a.y_eye_right;
    put("eye_" + lr + "_center", front_theta(s, xe, ye), ye);
    put("eye_" + lr + "_inner", front_theta(s, xe - side * p.eye_width / 2, ye), ye);
    put("eye_" + lr + "_outer", front_theta(s, xe + side * p.eye_width / 2, ye), ye);
    const double s_center = (p.eye_width / 2 + 1) / (p.eye_width + 6);
    const std::pair<const char*, double> brows[] = {
        {"inner", 0.0}, {"center", s_center}, {"outer", 1.0}};
    for (const auto& [part, sb] : brows) {
      const Eigen::Vector3d b = brow_point(s, side, sb);
      put("brow_" + lr + "_" + part, front_theta(s, b.x(), b.y()), b.y());
    }
    const double ya = a.y_sub + 5;
    put("alar_" + lr, front_theta(s, a.x_mid + side * p.nose_width / 2, ya), ya);
    put("mouth_" + lr, front_theta(s, a.x_mid + side * p.mouth_width / 2, a.y_mouth), a.y_mouth);
    // Ear top: the top of the ear outline (along its tilted axis), on the side.
    const double v = 0.93 * a.ear_ry, tilt = kEarTilt;
    const double z_top = a.z_ear_c - v * std::sin(tilt), y_top = a.y_ear_c + v * std::cos(tilt);
    put("ear_" + lr + "_top", side_theta(s, z_top, y_top, side), y_top);
    put("ear_" + lr + "_tragus", side_theta(s, a.z_tragus, a.y_tragus, side), a.y_tragus);
    const double y_tip = param.y(out.ut.at("nose_tip").y());
    put("cheek_" + lr, cheek_theta(s, y_tip, side), y_tip);
  }
  return out;
}

}  // namespace orthoface::sim::detail
