// Front-view features (seed 004 §4): position model first guess + local filters + mirroring.
#include "vision/front_features.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/feature_filters.h"

namespace orthoface::vision {

namespace {

Feature2d make(cv::Point2d p, double conf, const std::string& method) {
  Feature2d f;
  f.px = p;
  f.confidence = std::clamp(conf, 0.0, 1.0);
  f.method = method;
  return f;
}

double row_of(const std::map<std::string, double>& rows, const char* name, double fallback) {
  const auto it = rows.find(name);
  return it == rows.end() ? fallback : it->second;
}

// Centre line through the midpoints of symmetric pairs; roll also from the eye line.
CentreLine centre_from_pairs(const std::vector<std::pair<cv::Point2d, cv::Point2d>>& pairs,
                             double fallback_x, double fallback_y) {
  CentreLine c;
  c.centre_x = fallback_x;
  c.centre_y = fallback_y;
  if (pairs.empty()) return c;
  double sx = 0, sy = 0;
  for (const auto& [a, b] : pairs) sx += (a.x + b.x) / 2, sy += (a.y + b.y) / 2;
  c.centre_x = sx / pairs.size();
  c.centre_y = sy / pairs.size();
  // Roll from the first pair (the eyes): the axis is perpendicular to the line joining them.
  const cv::Point2d d = pairs.front().second - pairs.front().first;
  const double slope = d.x != 0 ? d.y / d.x : 0.0;
  c.roll_rad = std::atan(-slope);
  c.confidence = 0.5 + 0.5 * std::min(1.0, (pairs.size() - 1) / 2.0);
  return c;
}

// Face side x at row y with the ear removed: a quadratic x(row) fitted to the boundary around
// y, re-weighted so that outward bumps (the ears) stop pulling it out.
double cheek_x(const std::vector<cv::Point2d>& side, double y, double H, int outward) {
  std::vector<cv::Point2d> pts;
  for (const auto& p : side)
    if (std::abs(p.y - y) < 0.22 * H) pts.push_back(p);
  if (pts.size() < 6) return boundary_x(side, y);
  std::vector<double> w(pts.size(), 1.0);
  cv::Mat coef = cv::Mat::zeros(3, 1, CV_64F);
  for (int it = 0; it < 6; ++it) {
    cv::Mat A(int(pts.size()), 3, CV_64F), b(int(pts.size()), 1, CV_64F);
    for (size_t i = 0; i < pts.size(); ++i) {
      const double u = (pts[i].y - y) / H;
      A.at<double>(int(i), 0) = w[i];
      A.at<double>(int(i), 1) = w[i] * u;
      A.at<double>(int(i), 2) = w[i] * u * u;
      b.at<double>(int(i)) = w[i] * pts[i].x;
    }
    cv::solve(A, b, coef, cv::DECOMP_SVD);
    for (size_t i = 0; i < pts.size(); ++i) {
      const double u = (pts[i].y - y) / H;
      const double r =
          outward *
          (pts[i].x - (coef.at<double>(0) + coef.at<double>(1) * u + coef.at<double>(2) * u * u));
      w[i] = r > 1.0 ? 0.02 : 1.0;
    }
  }
  return coef.at<double>(0);
}

// How far below the subnasale row the mouth is looked for when the lip rows miss it.
constexpr double kMouthSearch = 0.3;

// Mouth at the profile's lip rows; when the views are not level (a real front and side photo
// taken at different heights) the lips lie off those rows, so a second search spans the band
// below the nose (position model: the mouth lies within 0.3 H under the subnasale).
MouthFound mouth_near_rows(const FilterContext& ctx, double x0, double r_sub, double r_lu,
                           double r_ll, double W, double H) {
  MouthFound m = find_mouth(ctx, x0, r_lu, r_ll, W, H);
  if (m.ok) return m;
  m = find_mouth(ctx, x0, r_sub + 0.06 * H, r_sub + (kMouthSearch - 0.04) * H, W, H);
  m.confidence *= 0.6;
  return m;
}

// Eye centres lie about this share of the head height under the nasion row (sim heads).
constexpr double kEyeUnderNasion = 0.015;

// Both eyes found, level with each other (roll under ~10 deg), apart like eyes, confident.
bool eye_pair_ok(const EyeFound& a, const EyeFound& b, double W, double H, double min_conf) {
  return a.ok && b.ok && std::abs(a.centre.y - b.centre.y) < 0.04 * H &&
         b.centre.x - a.centre.x > 0.25 * W && std::min(a.confidence, b.confidence) >= min_conf;
}

}  // namespace

cv::Point2d mirror_point(const CentreLine& line, cv::Point2d p) {
  const double t = std::tan(line.roll_rad);
  cv::Point2d d(t, 1.0);
  d *= 1.0 / std::hypot(t, 1.0);
  const cv::Point2d o(line.centre_x, line.centre_y);
  const cv::Point2d proj = o + d * (p - o).dot(d);
  return 2 * proj - p;
}

FrontFeatures front_features(const cv::Mat& bgr, const FrontBoundary& fb,
                             const std::map<std::string, double>& rows, double H) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("front_features: expected 8-bit BGR image");
  FrontFeatures out;
  if (fb.left.empty() || fb.right.empty()) {
    out.warnings.push_back("front view: no boundary, features not searched");
    return out;
  }
  if (H <= 0) H = (fb.bottom_row - fb.top_row) / 1.1;
  const double top = fb.top_row;
  // Midline rows: from the profile when given, else the position model (fractions of H).
  const double r_nasion = row_of(rows, "nose_bridge", top + 0.43 * H);
  const double r_tip = row_of(rows, "nose_tip", top + 0.58 * H);
  const double r_sub = row_of(rows, "subnasale", top + 0.65 * H);
  const double r_lu = row_of(rows, "lip_upper", top + 0.72 * H);
  const double r_ll = row_of(rows, "lip_lower", top + 0.76 * H);
  // Face width and centre on the forehead; when that row is far narrower than the face at the
  // nose tip (a profile row landing in the hair: views not level, a hair tuft), the nasion row.
  double r_fh = r_nasion - 0.15 * H;
  const auto width_at = [&](double r) { return boundary_x(fb.right, r) - boundary_x(fb.left, r); };
  if (width_at(r_fh) < 0.7 * width_at(r_tip)) r_fh = r_nasion;
  const double x0 = (boundary_x(fb.left, r_fh) + boundary_x(fb.right, r_fh)) / 2;
  const double W = width_at(r_fh);
  // The filters' windows: eyes and brows (x0 +- 0.62 W, from 0.14 H above the nasion row) down
  // to the mouth (0.04 H under the lower lip row) and the cheek skin beside the nose.
  const double box_top = std::min(r_nasion, r_lu) - 0.2 * H,
               box_bottom = std::max(r_ll, r_sub + kMouthSearch * H) + 0.1 * H;
  const cv::Rect box(cv::Point(int(x0 - 0.7 * W), int(box_top)),
                     cv::Point(int(x0 + 0.7 * W) + 2, int(box_bottom) + 2));
  const FilterContext ctx = make_filter_context(bgr, cv::Point2d(x0, r_tip + 0.06 * H), W, box);
  // Eyes: image-left eye is the subject's right eye.
  EyeFound er = find_eye(ctx, x0, r_nasion, W, H, true);
  EyeFound el = find_eye(ctx, x0, r_nasion, W, H, false);
  // No eye pair at the profile's nasion row but one a little above or below it: the views are
  // not level (a real front and side photo taken at different heights) or the profile's nasion
  // is off. The nearest such pair is taken; the other profile rows stay (on real pairs the
  // eye-to-nasion offset did not predict the nose and mouth rows).
  if (!rows.empty() && !eye_pair_ok(er, el, W, H, 0.6)) {
    for (double d : {0.04, -0.04, 0.08, -0.08, 0.12, -0.12, 0.16}) {
      const EyeFound a = find_eye(ctx, x0, r_nasion + d * H, W, H, true);
      const EyeFound b = find_eye(ctx, x0, r_nasion + d * H, W, H, false);
      if (!eye_pair_ok(a, b, W, H, 0.8)) continue;
      er = a, el = b;
      const double off = 0.5 * (a.centre.y + b.centre.y) - (r_nasion + kEyeUnderNasion * H);
      if (std::abs(off) > 0.03 * H)
        out.warnings.push_back("front view: eyes found " + std::to_string(int(std::lround(off))) +
                               " px off the side view's nasion row; views not level?");
      break;
    }
  }
  const MouthFound mouth = mouth_near_rows(ctx, x0, r_sub, r_lu, r_ll, W, H);
  const NoseFound nose = find_nose(ctx, x0, r_tip, r_sub, W, H);
  std::vector<std::pair<cv::Point2d, cv::Point2d>> pairs;
  if (er.ok && el.ok) pairs.push_back({er.centre, el.centre});
  if (mouth.ok) pairs.push_back({mouth.corner_image_left, mouth.corner_image_right});
  if (nose.ok) pairs.push_back({nose.alar_image_left, nose.alar_image_right});
  out.centre = centre_from_pairs(pairs, x0, r_tip);
  if (!(er.ok && el.ok)) out.centre.confidence *= 0.5;
  if (pairs.empty()) out.warnings.push_back("front view: centre line from the boundary only");
  add_eye_features(er, el, out);
  add_brow_features(ctx, er, el, W, H, out);
  add_nose_mouth_features(nose, mouth, out);
  // Midline points: on the centre line at the profile's rows.
  const auto on_line = [&](double y) {
    return cv::Point2d(
        out.centre.centre_x + std::tan(out.centre.roll_rad) * (y - out.centre.centre_y), y);
  };
  for (const char* n : {"forehead_top", "nose_bridge", "nose_tip", "subnasale", "lip_upper",
                        "lip_lower", "chin", "chin_bottom"}) {
    const auto it = rows.find(n);
    if (it != rows.end())
      out.features[n] =
          make(on_line(it->second), 0.7 * out.centre.confidence, "centre-line+profile-row");
  }
  if (rows.empty()) {  // front view alone: midline rows from the position model
    const double r_mouth =
        mouth.ok ? 0.5 * (mouth.corner_image_left.y + mouth.corner_image_right.y) : r_lu + 0.02 * H;
    // With both eyes and the mouth: nose rows at their usual share of the eye-to-mouth span.
    const bool em = er.ok && el.ok && mouth.ok;
    const double ye = 0.5 * (er.centre.y + el.centre.y), D = r_mouth - ye;
    const std::pair<const char*, double> guess[] = {{"forehead_top", top + 0.2 * H},
                                                    {"nose_bridge", em ? ye - 0.05 * D : r_nasion},
                                                    {"nose_tip", em ? ye + 0.62 * D : r_tip},
                                                    {"subnasale", em ? ye + 0.74 * D : r_sub},
                                                    {"lip_upper", r_mouth - 0.025 * H},
                                                    {"lip_lower", r_mouth + 0.035 * H},
                                                    {"chin", top + 0.93 * H},
                                                    {"chin_bottom", top + H}};
    for (const auto& [n, y] : guess)
      out.features[n] = make(on_line(y), 0.2 * out.centre.confidence, "position-model");
  }
  out.features["cheek_right"] =
      make({cheek_x(fb.left, r_tip, H, -1), r_tip}, fb.confidence, "boundary-without-ear");
  out.features["cheek_left"] =
      make({cheek_x(fb.right, r_tip, H, 1), r_tip}, fb.confidence, "boundary-without-ear");
  mirror_missing(out);
  return out;
}

}  // namespace orthoface::vision
