#include "vision/side_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/contour_chain.h"
#include "vision/curve_features.h"
#include "vision/edges.h"

namespace orthoface::vision {

void SideProfileOptions::check() const {
  if (!(control_spacing_px >= 3 && control_spacing_px <= 100))
    throw std::invalid_argument("SideProfileOptions: control_spacing_px must be in [3, 100]");
  fit.check();
}

namespace {

// Crown-to-chin height from the blob: a head is about 1.2x as tall as it is deep (front-back),
// and its depth is reached within about 0.9 depth below the crown.
double head_height_estimate(const RowExtent& e) {
  double m = 0;
  for (int r = e.top; r >= 0 && r <= e.bottom; ++r) {
    if (e.left[r] >= 0) m = std::max(m, double(e.right[r] - e.left[r] + 1));
    if (r - e.top > 0.9 * m && m > 10) break;
  }
  return 1.2 * m;
}

Feature2d feature(cv::Point2d p, double conf, const std::string& method) {
  Feature2d f;
  f.px = p;
  f.confidence = conf;
  f.method = method;
  return f;
}

// Refined dense profile: mask chain -> B-spline -> iterative fit on the probability edges.
std::vector<cv::Point2d> fitted_curve(const std::vector<cv::Point2d>& chain, const cv::Mat& prob,
                                      const SideProfileOptions& o, double* support) {
  const std::vector<cv::Point2d> pts = resample(chain, 2.0);
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += cv::norm(pts[i] - pts[i - 1]);
  const int nc = std::clamp(int(len / o.control_spacing_px), 6, 150);
  BSpline2d init = fit_bspline(pts, chord_parameters(pts), {}, nc, 0.05);
  ProfileFitOptions f = o.fit;
  f.num_control = nc;
  f.samples = std::max(nc * 4, int(len / 1.5));
  f.polarity = -1;  // the probability falls toward the left-hand normal (outside)
  f.search_px = 4.0;
  f.min_search_px = 1.5;
  f.iterations = 3;
  f.smoothness = 0.02;
  const ProfileFit fit = fit_profile_to_edges(init, edge_image(prob, {0.7, 0.1}), f);
  *support = fit.support;
  return resample(bspline_samples(fit.spline, std::max(50, int(len))), 1.0);
}

}  // namespace

bool profile_faces_left(const cv::Mat& mask, double* confidence) {
  const RowExtent e = row_extent(mask);
  if (confidence) *confidence = 0;
  if (e.top < 0) return true;
  const double h = head_height_estimate(e);
  // Two cues: the nose bump sticks out on the face side, and the neck stands behind the face.
  const cv::Point2d p = side_protrusions(e, int(e.top + 0.3 * h), int(e.top + 0.85 * h));
  const double bump = (p.x - p.y) / std::max(4.0, 0.04 * h);
  const double neck = neck_offset(e, h) / std::max(4.0, 0.05 * h);
  const double vote = std::clamp(bump, -2.0, 2.0) + 2.0 * std::clamp(neck, -2.0, 2.0);
  if (confidence) *confidence = std::clamp(std::abs(vote) / 2.0, 0.0, 1.0);
  return vote >= 0;
}

SideProfile side_profile(const cv::Mat& bgr, const cv::Mat& prob, const cv::Mat& mask,
                         const SideProfileOptions& o) {
  o.check();
  if (bgr.type() != CV_8UC3 || prob.type() != CV_32F || mask.type() != CV_8U ||
      bgr.size() != prob.size() || bgr.size() != mask.size())
    throw std::invalid_argument("side_profile: image, probability and mask differ in size/type");
  SideProfile sp;
  const RowExtent e = row_extent(mask);
  if (e.top < 0) {
    sp.warnings.push_back("side view: no head found");
    return sp;
  }
  sp.head_height_px = head_height_estimate(e);
  const int stop = std::min(e.bottom, int(e.top + 1.45 * sp.head_height_px));
  const std::vector<cv::Point2d> chain = front_chain(mask, stop);
  if (chain.size() < 40) {
    sp.warnings.push_back("side view: head blob too small for a profile");
    return sp;
  }
  double support = 0;
  sp.curve = fitted_curve(chain, prob, o, &support);
  sp.confidence = support;
  find_profile_landmarks(bgr, sp);
  if (e.top == 0) sp.warnings.push_back("side view: head touches the top border (crown cut off)");
  if (e.left[std::clamp(int(e.top + 0.6 * sp.head_height_px), 0, mask.rows - 1)] == 0)
    sp.warnings.push_back("side view: face touches the image border (profile cut off)");
  return sp;
}

}  // namespace orthoface::vision
