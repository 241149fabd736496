#include "vision/profile_fit.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orthoface::vision {

void ProfileFitOptions::check() const {
  if (num_control < 4 || num_control > 200)
    throw std::invalid_argument("ProfileFitOptions: num_control must be in [4, 200]");
  if (samples < num_control)
    throw std::invalid_argument("ProfileFitOptions: samples < num_control");
  if (iterations < 1 || iterations > 100)
    throw std::invalid_argument("ProfileFitOptions: iterations must be in [1, 100]");
  if (!(search_px > 0) || !(min_search_px > 0) || min_search_px > search_px)
    throw std::invalid_argument("ProfileFitOptions: need 0 < min_search_px <= search_px");
  if (!(smoothness >= 0)) throw std::invalid_argument("ProfileFitOptions: smoothness < 0");
  if (polarity < -1 || polarity > 1)
    throw std::invalid_argument("ProfileFitOptions: polarity must be -1, 0 or +1");
}

namespace {

struct Hit {
  bool found = false;
  double offset = 0;    // along the normal, pixels
  double strength = 0;  // edge response at the hit
};

// Strongest edge along the normal within +-range, preferring near ones (model prior).
Hit search_normal(const EdgeImage& e, cv::Point2d p, cv::Point2d n, double range, int polarity) {
  const double step = 0.5;
  const int m = int(std::ceil(range / step));
  std::vector<double> v(2 * m + 1);
  const cv::Point2d start = p - cv::Point2d(e.origin);  // the edge images' own coordinates
  for (int i = -m; i <= m; ++i) {
    const cv::Point2d q = start + (i * step) * n;
    const double g = sample(e.gx, q.x, q.y) * n.x + sample(e.gy, q.x, q.y) * n.y;
    v[i + m] = polarity == 0 ? std::abs(g) : std::max(0.0, polarity * g);
  }
  Hit h;
  double best = 0;
  int bi = -1;
  for (int i = 0; i <= 2 * m; ++i) {
    const double s = (i - m) * step / range;
    const double score = v[i] * (1.0 - 0.25 * s * s);
    if (v[i] > e.threshold && score > best) best = score, bi = i;
  }
  if (bi < 0) return h;
  double sub = 0;  // parabolic peak refinement
  if (bi > 0 && bi < 2 * m) {
    const double a = v[bi - 1], b = v[bi], c = v[bi + 1];
    const double den = a - 2 * b + c;
    if (den < 0) sub = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
  }
  h.found = true;
  h.offset = (bi - m + sub) * step;
  h.strength = v[bi];
  return h;
}

}  // namespace

ProfileFit fit_profile_to_edges(const BSpline2d& initial, const EdgeImage& edges,
                                const ProfileFitOptions& o) {
  o.check();
  if (initial.control.size() < 4)
    throw std::invalid_argument("fit_profile_to_edges: initial model needs >= 4 control points");
  if (edges.gx.empty() || edges.gx.size() != edges.gy.size())
    throw std::invalid_argument("fit_profile_to_edges: empty edge image");
  ProfileFit fit;
  fit.spline = initial;
  std::vector<double> t(o.samples), w(o.samples);
  std::vector<cv::Point2d> target(o.samples);
  for (int i = 0; i < o.samples; ++i) t[i] = double(i) / (o.samples - 1);
  double range = o.search_px;
  for (int it = 0; it < o.iterations; ++it) {
    int found = 0;
    double resid = 0;
    for (int i = 0; i < o.samples; ++i) {
      const cv::Point2d p = bspline_point(fit.spline, t[i]);
      const cv::Point2d tg = bspline_tangent(fit.spline, t[i]);
      const cv::Point2d n(-tg.y, tg.x);
      const Hit h = search_normal(edges, p, n, range, o.polarity);
      if (h.found) {
        target[i] = p + h.offset * n;
        w[i] = 1.0;
        ++found;
        resid += std::abs(h.offset);
      } else {
        target[i] = p;  // no edge: the model keeps its shape here, weakly
        w[i] = 0.05;
      }
    }
    fit.support = double(found) / o.samples;
    fit.mean_residual_px = found ? resid / found : 0.0;
    fit.spline = fit_bspline(target, t, w, o.num_control, o.smoothness);
    range = std::max(o.min_search_px, range * 0.6);
  }
  return fit;
}

}  // namespace orthoface::vision
