#include "vision/front_boundary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/bspline.h"
#include "vision/contour_chain.h"
#include "vision/edges.h"

namespace orthoface::vision {

void FrontBoundaryOptions::check() const {
  if (!(control_spacing_px >= 3 && control_spacing_px <= 100))
    throw std::invalid_argument("FrontBoundaryOptions: control_spacing_px must be in [3, 100]");
  fit.check();
}

namespace {

// One x per integer row in [r0, r1] from a dense curve: the outermost crossing of each row.
std::vector<cv::Point2d> per_row(const std::vector<cv::Point2d>& c, int r0, int r1, int outward) {
  std::vector<double> x(r1 - r0 + 1, std::numeric_limits<double>::quiet_NaN());
  for (size_t i = 1; i < c.size(); ++i) {
    const cv::Point2d a = c[i - 1], b = c[i];
    const double ylo = std::min(a.y, b.y), yhi = std::max(a.y, b.y);
    for (int r = std::max(r0, int(std::ceil(ylo))); r <= std::min(r1, int(std::floor(yhi))); ++r) {
      const double t = yhi > ylo ? (r - a.y) / (b.y - a.y) : 0.0;
      const double xr = a.x + t * (b.x - a.x);
      double& slot = x[r - r0];
      if (std::isnan(slot) || outward * (xr - slot) > 0) slot = xr;
    }
  }
  std::vector<cv::Point2d> out;
  for (int r = r0; r <= r1; ++r)
    if (!std::isnan(x[r - r0])) out.emplace_back(x[r - r0], r);
  return out;
}

// Mask chain of one side (left: first inside column per row), fitted and refined on edges.
std::vector<cv::Point2d> fit_side(const RowExtent& e, const EdgeImage& edges, int r0, int r1,
                                  bool left, const FrontBoundaryOptions& o, double* support) {
  std::vector<cv::Point2d> chain;
  // Top rows: start from the crown's middle so the curve covers the top arc too.
  for (int r = r0; r <= r1; ++r) {
    if (e.left[r] < 0) continue;
    const double x = left ? e.left[r] - 0.5 : e.right[r] + 0.5;  // the edge lies between pixels
    chain.emplace_back(x, r);
  }
  if (chain.size() < 8) return {};
  const std::vector<cv::Point2d> pts = resample(chain, 2.0);
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += cv::norm(pts[i] - pts[i - 1]);
  const int nc = std::clamp(int(len / o.control_spacing_px), 6, 150);
  const BSpline2d init = fit_bspline(pts, chord_parameters(pts), {}, nc, 0.05);
  ProfileFitOptions f = o.fit;
  f.num_control = nc;
  f.samples = std::max(nc * 4, int(len / 1.5));
  f.polarity = left ? -1 : 1;  // walking down, the left-hand normal points image-left
  f.search_px = 4.0;
  f.min_search_px = 1.5;
  f.iterations = 3;
  f.smoothness = 0.02;
  const ProfileFit fit = fit_profile_to_edges(init, edges, f);
  *support = fit.support;
  return per_row(bspline_samples(fit.spline, std::max(50, int(2 * len))), r0, r1, left ? -1 : 1);
}

}  // namespace

double boundary_x(const std::vector<cv::Point2d>& side, double y) {
  if (side.empty()) return std::numeric_limits<double>::quiet_NaN();
  if (y <= side.front().y) return side.front().x;
  if (y >= side.back().y) return side.back().x;
  const auto it = std::lower_bound(side.begin(), side.end(), y,
                                   [](const cv::Point2d& p, double v) { return p.y < v; });
  const cv::Point2d b = *it, a = *(it - 1);
  return b.y > a.y ? a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x) : b.x;
}

FrontBoundary front_boundary(const cv::Mat& prob, const cv::Mat& mask, int bottom_row,
                             const FrontBoundaryOptions& o) {
  o.check();
  if (prob.type() != CV_32F || mask.type() != CV_8U || prob.size() != mask.size())
    throw std::invalid_argument("front_boundary: probability and mask differ in size/type");
  FrontBoundary fb;
  const RowExtent e = row_extent(mask);
  if (e.top < 0) {
    fb.warnings.push_back("front view: no head found");
    return fb;
  }
  for (int r = e.top; r <= e.bottom; ++r)
    if (e.left[r] >= 0)
      fb.head_width_px = std::max(fb.head_width_px, double(e.right[r] - e.left[r]));
  if (bottom_row < 0) bottom_row = int(e.top + 1.45 * fb.head_width_px);
  fb.top_row = e.top;
  fb.bottom_row = std::clamp(bottom_row, e.top, e.bottom);
  // Edges near the blob only: its box plus the fit's search range and the filters' support.
  const int pad = 12;
  const cv::Rect box = cv::boundingRect(mask);
  const EdgeImage edges =
      edge_image(prob, {0.7, 0.1},
                 cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad));
  double sl = 0, sr = 0;
  fb.left = fit_side(e, edges, fb.top_row, fb.bottom_row, true, o, &sl);
  fb.right = fit_side(e, edges, fb.top_row, fb.bottom_row, false, o, &sr);
  fb.confidence = 0.5 * (sl + sr);
  if (fb.left.empty() || fb.right.empty()) fb.warnings.push_back("front view: boundary not found");
  if (e.top == 0) fb.warnings.push_back("front view: head touches the top border (crown cut off)");
  for (int r = fb.top_row; r <= fb.bottom_row; ++r)
    if (e.left[r] == 0 || e.right[r] == mask.cols - 1) {
      fb.warnings.push_back("front view: head touches the side border (silhouette cut off)");
      fb.confidence *= 0.5;
      break;
    }
  return fb;
}

}  // namespace orthoface::vision
