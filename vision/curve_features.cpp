#include "vision/curve_features.h"

#include <algorithm>
#include <cmath>

namespace orthoface::vision {

std::vector<Extremum> alternating_extrema(const std::vector<double>& v, double prominence) {
  std::vector<Extremum> out;
  if (v.size() < 3) return out;
  int hi = 0, lo = 0;
  int trend = 0;  // +1 rising (looking for a max), -1 falling, 0 not yet known
  for (int i = 1; i < int(v.size()); ++i) {
    if (trend >= 0 && v[i] > v[hi]) hi = i;
    if (trend <= 0 && v[i] < v[lo]) lo = i;
    if (trend >= 0 && v[hi] - v[i] >= prominence) {
      if (hi > 0) out.push_back({hi, true});  // the sequence start is not an extremum
      trend = -1;
      lo = i;
    } else if (trend <= 0 && v[i] - v[lo] >= prominence) {
      if (lo > 0) out.push_back({lo, false});
      trend = 1;
      hi = i;
    }
  }
  return out;
}

int deepest_behind_chord(const std::vector<cv::Point2d>& c, int a, int b, double* depth) {
  if (depth) *depth = 0;
  if (b - a < 2) return a;
  const cv::Point2d d = c[b] - c[a];
  const double len = std::hypot(d.x, d.y);
  if (len < 1e-9) return a;
  // Signed distance from the chord, positive toward +x of the chord's left-facing profile.
  cv::Point2d n(d.y, -d.x);
  n *= 1.0 / len;
  if (n.x < 0) n = -n;
  int best = a;
  double bd = 0;
  for (int i = a + 1; i < b; ++i) {
    const double s = (c[i] - c[a]).dot(n);
    if (s > bd) bd = s, best = i;
  }
  if (depth) *depth = bd;
  return best;
}

int tangent_closest(const std::vector<cv::Point2d>& c, int a, int b, double angle) {
  int best = a;
  double bd = 1e9;
  for (int i = std::max(a, 1); i <= b && i + 1 < int(c.size()); ++i) {
    const cv::Point2d d = c[i + 1] - c[i - 1];
    double diff = std::atan2(d.y, d.x) - angle;
    diff = std::abs(std::remainder(diff, 2 * M_PI));
    if (diff < bd) bd = diff, best = i;
  }
  return best;
}

}  // namespace orthoface::vision
