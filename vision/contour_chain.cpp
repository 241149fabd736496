#include "vision/contour_chain.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace orthoface::vision {

namespace {

// Index of the first non-zero byte of p[0, n), n when none; skips zero bytes 8 at a time.
int first_set(const uchar* p, int n) {
  int c = 0;
  for (; c + 8 <= n; c += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + c, 8);
    if (w) break;
  }
  while (c < n && !p[c]) ++c;
  return c;
}

}  // namespace

RowExtent row_extent(const cv::Mat& mask) {
  if (mask.empty() || mask.type() != CV_8U)
    throw std::invalid_argument("row_extent: expected a CV_8U mask");
  RowExtent e;
  e.left.assign(mask.rows, -1);
  e.right.assign(mask.rows, -1);
  for (int r = 0; r < mask.rows; ++r) {
    const uchar* p = mask.ptr<uchar>(r);
    const int c = first_set(p, mask.cols);
    if (c == mask.cols) continue;
    int d = mask.cols - 1;
    while (d > c && !p[d]) --d;
    e.left[r] = c;
    e.right[r] = d;
    if (e.top < 0) e.top = r;
    e.bottom = r;
  }
  return e;
}

std::vector<cv::Point2d> front_chain(const cv::Mat& mask, int stop_row) {
  const cv::Rect box = cv::boundingRect(mask);  // contours of the blob's box only
  if (box.empty()) return {};
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask(box).clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, box.tl());
  if (contours.empty()) return {};
  const auto& c =
      *std::max_element(contours.begin(), contours.end(),
                        [](const auto& a, const auto& b) { return a.size() < b.size(); });
  const int n = int(c.size());
  if (n < 10) return {};
  // Top-most point; among equals the left-most, so the walk starts at the crown's front.
  int top = 0;
  for (int i = 1; i < n; ++i)
    if (c[i].y < c[top].y || (c[i].y == c[top].y && c[i].x < c[top].x)) top = i;
  // Walk the direction that heads left first.
  int dir = 1;
  {
    const int k = std::min(20, n / 4);
    const int xa = c[(top + k) % n].x, xb = c[(top - k + n) % n].x;
    dir = xa <= xb ? 1 : -1;
  }
  std::vector<cv::Point2d> chain;
  for (int s = 0; s < n; ++s) {
    const cv::Point& p = c[((top + dir * s) % n + n) % n];
    chain.emplace_back(p.x, p.y);
    if (p.y >= stop_row) break;
  }
  return chain;
}

cv::Point2d side_protrusions(const RowExtent& e, int r0, int r1) {
  r0 = std::max(r0, 0);
  r1 = std::min<int>(r1, int(e.left.size()));
  double peak[2] = {0, 0};
  for (int side = 0; side < 2; ++side) {
    // Outward coordinate per row: left side outward = -x, right side outward = +x.
    std::vector<double> ys, vs;
    for (int r = r0; r < r1; ++r) {
      if (e.left[r] < 0) continue;
      ys.push_back(r);
      vs.push_back(side == 0 ? -e.left[r] : e.right[r]);
    }
    if (ys.size() < 8) continue;
    // Quadratic least-squares fit; the peak is the largest outward residual.
    cv::Mat A(int(ys.size()), 3, CV_64F), b(int(ys.size()), 1, CV_64F), x;
    const double ym = (r0 + r1) / 2.0, ys_scale = std::max(1.0, (r1 - r0) / 2.0);
    for (size_t i = 0; i < ys.size(); ++i) {
      const double u = (ys[i] - ym) / ys_scale;
      A.at<double>(int(i), 0) = 1;
      A.at<double>(int(i), 1) = u;
      A.at<double>(int(i), 2) = u * u;
      b.at<double>(int(i)) = vs[i];
    }
    cv::solve(A, b, x, cv::DECOMP_SVD);
    for (size_t i = 0; i < ys.size(); ++i) {
      const double u = (ys[i] - ym) / ys_scale;
      const double fitv = x.at<double>(0) + x.at<double>(1) * u + x.at<double>(2) * u * u;
      peak[side] = std::max(peak[side], vs[i] - fitv);
    }
  }
  return {peak[0], peak[1]};
}

double neck_offset(const RowExtent& e, double h) {
  if (e.top < 0) return 0;
  double wmax = -1, head_mid = 0;
  for (int r = e.top; r <= std::min(e.bottom, int(e.top + 0.8 * h)); ++r)
    if (e.left[r] >= 0 && e.right[r] - e.left[r] > wmax)
      wmax = e.right[r] - e.left[r], head_mid = 0.5 * (e.left[r] + e.right[r]);
  double s = 0;
  int n = 0;
  for (int r = int(e.top + 1.0 * h); r <= std::min(e.bottom, int(e.top + 1.15 * h)); ++r)
    if (r >= 0 && e.left[r] >= 0) s += 0.5 * (e.left[r] + e.right[r]), ++n;
  return n ? s / n - head_mid : 0.0;
}

double head_width(const RowExtent& e, bool stop_at_widening) {
  if (e.top < 0) return 0;
  const auto width = [&](int r) {
    return e.left[r] >= 0 ? double(e.right[r] - e.left[r] + 1) : 0.0;
  };
  double widest = 0;  // of the whole blob: a hair tuft on top is far narrower
  for (int r = e.top; r <= e.bottom; ++r) widest = std::max(widest, width(r));
  std::vector<double> m{0.0};  // m[i]: widest row among the first i rows
  for (int r = e.top; r <= e.bottom; ++r) {
    const double mr = m.back();
    const int k = std::max(3, int(0.2 * mr));
    const double grow = r - k >= e.top ? width(r) - width(r - k) : 1e9;
    // Front view: past half a head below the top, a blob widening by 1.5 px a row over 0.2 m
    // rows is reaching the shoulders (or a hood or collar around the head): the width from
    // before the widening.
    if (stop_at_widening && mr > 0.25 * widest && r - e.top > 0.5 * mr && grow > 1.5 * k)
      return m[size_t(r - k - e.top)];
    if (r - e.top > 0.9 * mr && mr > 10) break;
    m.push_back(std::max(mr, width(r)));
  }
  return m.back();
}

std::vector<cv::Point2d> resample(const std::vector<cv::Point2d>& p, double step) {
  if (!(step > 0)) throw std::invalid_argument("resample: step must be > 0");
  if (p.size() < 2) return p;
  std::vector<cv::Point2d> out{p.front()};
  double carry = 0;
  for (size_t i = 1; i < p.size(); ++i) {
    const cv::Point2d d = p[i] - p[i - 1];
    const double len = std::sqrt(d.x * d.x + d.y * d.y);
    double s = step - carry;
    while (s <= len) {
      out.push_back(p[i - 1] + d * (s / len));
      s += step;
    }
    carry = len - (s - step);
  }
  if (std::hypot(out.back().x - p.back().x, out.back().y - p.back().y) > 1e-6)
    out.push_back(p.back());
  return out;
}

}  // namespace orthoface::vision
