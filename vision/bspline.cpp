#include "vision/bspline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace orthoface::vision {

namespace {

// Clamped uniform knots for n control points, degree 3: n + 4 knots in [0, 1].
double knot(int i, int n) {
  const int spans = n - 3;
  return std::clamp(double(i - 3) / spans, 0.0, 1.0);
}

// The 4 non-zero basis values at t and the index of the first one (Cox-de Boor).
int basis(double t, int n, double b[4]) {
  const int spans = n - 3;
  t = std::clamp(t, 0.0, 1.0);
  int span = std::min(int(t * spans), spans - 1) + 3;  // knot index k with knot(k) <= t < knot(k+1)
  double left[4], right[4];
  b[0] = 1.0;
  for (int j = 1; j <= 3; ++j) {
    left[j] = t - knot(span + 1 - j, n);
    right[j] = knot(span + j, n) - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double den = right[r + 1] + left[j - r];
      const double tmp = den > 0 ? b[r] / den : 0.0;
      b[r] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    b[j] = saved;
  }
  return span - 3;
}

constexpr int kBand = 4;  // diagonal + 3 super-diagonals

// In-place Cholesky A = L L^T of a symmetric positive definite band matrix (band[j][k] =
// A(j, j + k)); afterwards band[j][k] = L(j + k, j). O(n) instead of the dense O(n^3).
void banded_cholesky(std::vector<std::array<double, kBand>>& a) {
  const int n = int(a.size());
  for (int j = 0; j < n; ++j) {
    double d = a[j][0];
    for (int k = 1; k < kBand && j - k >= 0; ++k) d -= a[j - k][k] * a[j - k][k];
    d = std::sqrt(std::max(d, 1e-300));
    a[j][0] = d;
    for (int i = 1; i < kBand && j + i < n; ++i) {
      double v = a[j][i];
      for (int k = 1; k + i < kBand && j - k >= 0; ++k) v -= a[j - k][k] * a[j - k][k + i];
      a[j][i] = v / d;
    }
  }
}

// Solves L L^T x = b in place with the factor from banded_cholesky.
void banded_solve(const std::vector<std::array<double, kBand>>& l, std::vector<double>& b) {
  const int n = int(l.size());
  for (int j = 0; j < n; ++j) {
    for (int k = 1; k < kBand && j - k >= 0; ++k) b[j] -= l[j - k][k] * b[j - k];
    b[j] /= l[j][0];
  }
  for (int j = n - 1; j >= 0; --j) {
    for (int k = 1; k < kBand && j + k < n; ++k) b[j] -= l[j][k] * b[j + k];
    b[j] /= l[j][0];
  }
}

void require_control(const BSpline2d& s, const char* fn) {
  if (s.control.size() < 4)
    throw std::invalid_argument(std::string(fn) +
                                ": a cubic B-spline needs at least 4 control "
                                "points, got " +
                                std::to_string(s.control.size()));
}

}  // namespace

cv::Point2d bspline_point(const BSpline2d& s, double t) {
  require_control(s, "bspline_point");
  double b[4];
  const int first = basis(t, int(s.control.size()), b);
  cv::Point2d p(0, 0);
  for (int k = 0; k < 4; ++k) p += b[k] * s.control[first + k];
  return p;
}

cv::Point2d bspline_tangent(const BSpline2d& s, double t) {
  require_control(s, "bspline_tangent");
  const double h = 1e-4;
  const double t0 = std::max(0.0, t - h), t1 = std::min(1.0, t + h);
  cv::Point2d d = bspline_point(s, t1) - bspline_point(s, t0);
  const double len = std::sqrt(d.x * d.x + d.y * d.y);
  return len > 1e-12 ? d / len : cv::Point2d(0, 0);
}

std::vector<cv::Point2d> bspline_samples(const BSpline2d& s, int count) {
  if (count < 2) throw std::invalid_argument("bspline_samples: count must be >= 2");
  std::vector<cv::Point2d> out(count);
  for (int i = 0; i < count; ++i) out[i] = bspline_point(s, double(i) / (count - 1));
  return out;
}

BSpline2d fit_bspline(const std::vector<cv::Point2d>& points, const std::vector<double>& t,
                      const std::vector<double>& w, int num_control, double smoothness) {
  if (points.size() != t.size() || (!w.empty() && w.size() != points.size()))
    throw std::invalid_argument("fit_bspline: points, parameters and weights differ in size");
  if (num_control < 4) throw std::invalid_argument("fit_bspline: num_control must be >= 4");
  int used = 0;
  for (size_t i = 0; i < points.size(); ++i) used += (w.empty() || w[i] > 0) ? 1 : 0;
  if (used < 2) throw std::invalid_argument("fit_bspline: fewer than 2 weighted points");
  const int n = num_control;
  // Normal equations: cubic basis functions overlap 4 at a time and the regulariser couples 3
  // neighbours, so A is symmetric with half-bandwidth 3; band[j][k] holds A(j, j + k).
  std::vector<std::array<double, kBand>> band(n, std::array<double, kBand>{});
  std::vector<double> bx(n, 0.0), by(n, 0.0);
  for (size_t i = 0; i < points.size(); ++i) {
    const double wi = w.empty() ? 1.0 : w[i];
    if (wi <= 0) continue;
    double b[4];
    const int f = basis(t[i], n, b);
    for (int k = 0; k < 4; ++k) {
      for (int l = k; l < 4; ++l) band[f + k][l - k] += wi * b[k] * b[l];
      bx[f + k] += wi * b[k] * points[i].x;
      by[f + k] += wi * b[k] * points[i].y;
    }
  }
  // Second-difference regulariser, plus a tiny ridge so under-determined spans stay defined.
  const double reg = smoothness + 1e-9;
  for (int j = 1; j + 1 < n; ++j) {
    const double c[3] = {1, -2, 1};
    for (int a = 0; a < 3; ++a)
      for (int b2 = a; b2 < 3; ++b2) band[j - 1 + a][b2 - a] += reg * c[a] * c[b2];
  }
  for (int j = 0; j < n; ++j) band[j][0] += 1e-9;
  banded_cholesky(band);
  banded_solve(band, bx);
  banded_solve(band, by);
  BSpline2d s;
  s.control.resize(n);
  for (int j = 0; j < n; ++j) s.control[j] = {bx[j], by[j]};
  return s;
}

std::vector<double> chord_parameters(const std::vector<cv::Point2d>& p) {
  if (p.empty()) throw std::invalid_argument("chord_parameters: empty polyline");
  std::vector<double> t(p.size(), 0.0);
  for (size_t i = 1; i < p.size(); ++i) t[i] = t[i - 1] + cv::norm(p[i] - p[i - 1]);
  const double total = t.back();
  for (double& v : t) v = total > 0 ? v / total : 0.0;
  if (total <= 0)
    for (size_t i = 0; i < p.size(); ++i) t[i] = p.size() > 1 ? double(i) / (p.size() - 1) : 0;
  return t;
}

}  // namespace orthoface::vision
