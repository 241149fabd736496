#include "vision/edges.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::vision {

void EdgeOptions::check() const {
  if (!(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0))
    throw std::invalid_argument("EdgeOptions: blur_sigma_px must be in [0, 20]");
  if (!(threshold_fraction > 0.0 && threshold_fraction < 1.0))
    throw std::invalid_argument("EdgeOptions: threshold_fraction must be in (0, 1)");
}

namespace {

// 99th percentile of a non-negative CV_32F image, from a 256-bin histogram up to its max;
// `zeros` more zero-valued pixels (sampled 1 in 4, like the image) join the count.
double high_percentile(const cv::Mat& m, long zeros) {
  double hi = 0;
  cv::minMaxLoc(m, nullptr, &hi);
  if (hi <= 0) return 0;
  std::vector<int> hist(256, 0);
  const double s = 255.0 / hi;
  for (int r = 0; r < m.rows; r += 2) {
    const float* p = m.ptr<float>(r);
    for (int c = 0; c < m.cols; c += 2) ++hist[std::min(255, int(p[c] * s))];
  }
  long total = zeros / 4;
  for (int h : hist) total += h;
  long acc = 0;
  for (int b = 255; b >= 0; --b) {
    acc += hist[b];
    if (acc >= total / 100) return (b + 0.5) / s;
  }
  return hi;
}

}  // namespace

EdgeImage edge_image(const cv::Mat& image, const EdgeOptions& options) {
  if (image.empty()) throw std::invalid_argument("edge_image: empty image");
  return edge_image(image, options, cv::Rect(0, 0, image.cols, image.rows));
}

EdgeImage edge_image(const cv::Mat& image, const EdgeOptions& options, const cv::Rect& roi_in) {
  options.check();
  if (image.empty()) throw std::invalid_argument("edge_image: empty image");
  if (image.channels() != 1)
    throw std::invalid_argument("edge_image: expected one channel, got " +
                                std::to_string(image.channels()));
  const cv::Rect roi = roi_in & cv::Rect(0, 0, image.cols, image.rows);
  if (roi.empty()) throw std::invalid_argument("edge_image: region outside the image");
  cv::Mat f;
  image(roi).convertTo(f, CV_32F);
  if (options.blur_sigma_px > 0) cv::GaussianBlur(f, f, cv::Size(), options.blur_sigma_px);
  EdgeImage e;
  e.origin = roi.tl();
  // Sobel 3x3 scaled by 1/8 so the gradient is in intensity units per pixel.
  cv::Sobel(f, e.gx, CV_32F, 1, 0, 3, 0.125);
  cv::Sobel(f, e.gy, CV_32F, 0, 1, 3, 0.125);
  cv::magnitude(e.gx, e.gy, e.magnitude);
  e.threshold =
      options.threshold_fraction * high_percentile(e.magnitude, long(image.total() - roi.area()));
  cv::compare(e.magnitude, e.threshold, e.edges, cv::CMP_GT);
  return e;
}

namespace {

// Bilinear BGR colour at (x, y), index coordinates, clamped to the image.
cv::Vec3d colour_at(const cv::Mat& bgr, double x, double y) {
  x = std::clamp(x, 0.0, double(bgr.cols - 1));
  y = std::clamp(y, 0.0, double(bgr.rows - 1));
  const int x0 = std::min(int(x), std::max(0, bgr.cols - 2));
  const int y0 = std::min(int(y), std::max(0, bgr.rows - 2));
  const int x1 = std::min(x0 + 1, bgr.cols - 1), y1 = std::min(y0 + 1, bgr.rows - 1);
  const double ax = x - x0, ay = y - y0;
  const cv::Vec3d a = bgr.at<cv::Vec3b>(y0, x0), b = bgr.at<cv::Vec3b>(y0, x1);
  const cv::Vec3d c = bgr.at<cv::Vec3b>(y1, x0), d = bgr.at<cv::Vec3b>(y1, x1);
  return (1 - ay) * ((1 - ax) * a + ax * b) + ay * ((1 - ax) * c + ax * d);
}

}  // namespace

std::vector<cv::Point2d> snap_to_colour_step(const cv::Mat& bgr,
                                             const std::vector<cv::Point2d>& points,
                                             const std::vector<cv::Point2d>& directions,
                                             double range_px, double min_step) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("snap_to_colour_step: expected a non-empty 8-bit BGR image");
  if (points.size() != directions.size())
    throw std::invalid_argument("snap_to_colour_step: points and directions differ in size");
  if (!(range_px > 0 && range_px <= 20) || !(min_step >= 0))
    throw std::invalid_argument("snap_to_colour_step: need 0 < range_px <= 20 and min_step >= 0");
  constexpr double kStep = 0.25;  // search step along the direction, pixels
  const int m = int(std::ceil(range_px / kStep));
  std::vector<cv::Point2d> out = points;
  constexpr int kHalf = 2;  // half a pixel in search steps
  std::vector<double> g(2 * m + 1);
  std::vector<cv::Vec3d> c(2 * (m + kHalf) + 1);  // colours at offsets -m-2 .. m+2 steps
  for (size_t i = 0; i < points.size(); ++i) {
    const cv::Point2d n = directions[i] * (1.0 / std::max(1e-12, cv::norm(directions[i])));
    for (int j = -m - kHalf; j <= m + kHalf; ++j) {
      const cv::Point2d q = points[i] + (j * kStep) * n;
      c[j + m + kHalf] = colour_at(bgr, q.x, q.y);
    }
    for (int k = -m; k <= m; ++k) {  // colour difference across one pixel centred at offset k
      const cv::Vec3d d = c[k + m + 2 * kHalf] - c[k + m];
      g[k + m] = std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]);
    }
    const int best = int(std::max_element(g.begin(), g.end()) - g.begin());
    if (g[best] < min_step || g[best] <= 0) continue;
    double sub = 0;  // parabolic peak refinement
    if (best > 0 && best < 2 * m) {
      const double a = g[best - 1], b = g[best], c = g[best + 1], den = a - 2 * b + c;
      if (den < 0) sub = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
    }
    out[i] = points[i] + ((best - m + sub) * kStep) * n;
  }
  return out;
}

float sample(const cv::Mat& m, double x, double y) {
  x = std::clamp(x, 0.0, double(m.cols - 1));
  y = std::clamp(y, 0.0, double(m.rows - 1));
  const int x0 = std::min(int(x), m.cols - 2 < 0 ? 0 : m.cols - 2);
  const int y0 = std::min(int(y), m.rows - 2 < 0 ? 0 : m.rows - 2);
  const int x1 = std::min(x0 + 1, m.cols - 1), y1 = std::min(y0 + 1, m.rows - 1);
  const float ax = float(x - x0), ay = float(y - y0);
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x1]);
}

}  // namespace orthoface::vision
