#include "vision/foreground.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::vision {

void SegmentOptions::check() const {
  if (!(border_fraction > 0.0 && border_fraction < 0.3))
    throw std::invalid_argument("SegmentOptions: border_fraction must be in (0, 0.3)");
  if (!(min_head_fraction > 0.0 && min_head_fraction < 0.9))
    throw std::invalid_argument("SegmentOptions: min_head_fraction must be in (0, 0.9)");
}

namespace {

constexpr int kBins = kColourLevels;

// Colour counts of the left, right and top border strips (the bottom holds the body).
std::vector<float> border_counts(const cv::Mat& bgr, double fraction, bool use_left,
                                 bool use_right) {
  std::vector<float> h(kColourBins, 0.f);
  const int bw = std::max(2, int(bgr.cols * fraction)), bh = std::max(2, int(bgr.rows * fraction));
  const int side_rows = int(bgr.rows * 0.75);
  for (int r = 0; r < bgr.rows; ++r) {
    const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(r);
    if (r < bh) {  // top strip: outer thirds only, the crown may reach the top centre
      for (int c = 0; c < bgr.cols / 3; c += 2) h[colour_bin(p[c])] += 1;
      for (int c = bgr.cols - bgr.cols / 3; c < bgr.cols; c += 2) h[colour_bin(p[c])] += 1;
    } else if (r < side_rows) {
      for (int c = 0; use_left && c < bw; c += 2) h[colour_bin(p[c])] += 1;
      for (int c = bgr.cols - bw; use_right && c < bgr.cols; c += 2) h[colour_bin(p[c])] += 1;
    }
  }
  return h;
}

// Colour density of the border strips relative to a uniform spread over all bins.
std::vector<float> border_histogram(const cv::Mat& bgr, double fraction, bool use_left,
                                    bool use_right) {
  const std::vector<float> h = border_counts(bgr, fraction, use_left, use_right);
  std::vector<float> s = spread_to_neighbours(h, 0.25f);
  double total = 0;
  for (float v : h) total += v;
  // Density relative to a uniform spread over all bins.
  for (float& v : s) v = float(v / std::max(1.0, total) * s.size());
  return s;
}

cv::Mat from_border_model(const cv::Mat& bgr, const SegmentOptions& o) {
  cv::Mat smooth;
  cv::GaussianBlur(bgr, smooth, cv::Size(5, 5), 1.0);
  std::vector<float> prob =
      border_histogram(smooth, o.border_fraction, o.sample_left, o.sample_right);
  for (float& d : prob)
    d = 1.f - std::min(1.f, d / 4.f);  // density >= 4x uniform: surely background
  cv::Mat p(bgr.size(), CV_32F);
  for (int r = 0; r < bgr.rows; ++r) {
    const cv::Vec3b* s = smooth.ptr<cv::Vec3b>(r);
    float* o = p.ptr<float>(r);
    for (int c = 0; c < bgr.cols; ++c) o[c] = prob[colour_bin(s[c])];
  }
  return p;
}

cv::Mat from_background(const cv::Mat& bgr, const cv::Mat& bg) {
  cv::Mat a, b, diff;
  cv::GaussianBlur(bgr, a, cv::Size(5, 5), 1.0);
  cv::GaussianBlur(bg, b, cv::Size(5, 5), 1.0);
  cv::absdiff(a, b, diff);
  std::vector<cv::Mat> ch;
  cv::split(diff, ch);
  cv::Mat d = cv::max(cv::max(ch[0], ch[1]), ch[2]);
  // Noise level: median difference (most of a frame is background).
  std::vector<int> hist(256, 0);
  for (int r = 0; r < d.rows; ++r)
    for (int c = 0; c < d.cols; ++c) ++hist[d.at<uchar>(r, c)];
  int med = 0;
  for (long acc = 0; med < 255 && (acc += hist[med]) < long(d.total()) / 2;) ++med;
  const float lo = float(std::max(6, 3 * med)), hi = lo * 2.5f;
  cv::Mat p;
  d.convertTo(p, CV_32F);
  p = (p - lo) / (hi - lo);
  cv::threshold(p, p, 1.0, 1.0, cv::THRESH_TRUNC);
  cv::threshold(p, p, 0.0, 0.0, cv::THRESH_TOZERO);
  return p;
}

}  // namespace

std::vector<float> spread_to_neighbours(const std::vector<float>& counts, float neighbour_weight) {
  if (counts.size() != size_t(kColourBins))
    throw std::invalid_argument("spread_to_neighbours: the counts must have " +
                                std::to_string(kColourBins) + " colour bins");
  std::vector<float> s(counts.size(), 0.f);
  for (int b = 0; b < kBins; ++b)
    for (int g = 0; g < kBins; ++g)
      for (int r = 0; r < kBins; ++r) {
        const float v = counts[size_t((b * kBins + g) * kBins + r)];
        if (v == 0) continue;
        for (int db = -1; db <= 1; ++db)
          for (int dg = -1; dg <= 1; ++dg)
            for (int dr = -1; dr <= 1; ++dr) {
              const int bb = b + db, gg = g + dg, rr = r + dr;
              if (bb < 0 || gg < 0 || rr < 0 || bb >= kBins || gg >= kBins || rr >= kBins) continue;
              const float w = (db == 0 && dg == 0 && dr == 0) ? 1.f : neighbour_weight;
              s[size_t((bb * kBins + gg) * kBins + rr)] += w * v;
            }
      }
  return s;
}

cv::Mat foreground_probability(const cv::Mat& bgr, const cv::Mat& background,
                               const SegmentOptions& options) {
  options.check();
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("foreground_probability: expected 8-bit BGR image");
  if (background.empty()) return from_border_model(bgr, options);
  if (background.size() != bgr.size() || background.type() != CV_8UC3)
    throw std::invalid_argument("foreground_probability: background frame is " +
                                std::to_string(background.cols) + "x" +
                                std::to_string(background.rows) + ", image is " +
                                std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
  return from_background(bgr, background);
}

int border_colour_count(const cv::Mat& bgr, const SegmentOptions& options) {
  options.check();
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("border_colour_count: expected 8-bit BGR image");
  // The strips smoothed as the border model smooths the whole photo (their neighbours read).
  cv::Mat smooth = bgr.clone();
  const int bw = std::max(2, int(bgr.cols * options.border_fraction)) + 2;
  const int bh = std::max(2, int(bgr.rows * options.border_fraction)) + 2;
  const cv::Rect all(0, 0, bgr.cols, bgr.rows);
  for (const cv::Rect& strip : {cv::Rect(0, 0, bgr.cols, bh), cv::Rect(0, 0, bw, bgr.rows),
                                cv::Rect(bgr.cols - bw, 0, bw, bgr.rows)}) {
    const cv::Rect r = strip & all;
    if (r.area() > 0) cv::GaussianBlur(bgr(r), smooth(r), cv::Size(5, 5), 1.0);
  }
  std::vector<float> h =
      border_counts(smooth, options.border_fraction, options.sample_left, options.sample_right);
  double total = 0;
  for (float v : h) total += v;
  std::sort(h.rbegin(), h.rend());
  int n = 0;
  for (double acc = 0; n < int(h.size()) && acc < 0.95 * total;) acc += h[n++];
  return n;
}

cv::Mat head_mask(const cv::Mat& probability, const SegmentOptions& options, int* num_blobs) {
  options.check();
  if (probability.empty() || probability.type() != CV_32F)
    throw std::invalid_argument("head_mask: expected a CV_32F probability map");
  cv::Mat m;
  cv::compare(probability, 0.5, m, cv::CMP_GT);
  const cv::Mat k = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5));
  cv::morphologyEx(m, m, cv::MORPH_OPEN, k);
  cv::morphologyEx(m, m, cv::MORPH_CLOSE, k);
  // Blobs as outer contours (several times faster than labelling the components); a blob's
  // area counts its holes, which are filled anyway.
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(m, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<double> areas(contours.size());
  int best = -1;
  double best_score = 0;
  const double cx = m.cols / 2.0, diag = std::hypot(m.cols, m.rows);
  for (size_t i = 0; i < contours.size(); ++i) {
    const cv::Moments mo = cv::moments(contours[i]);
    areas[i] = mo.m00;
    if (mo.m00 < options.min_head_fraction * m.total()) continue;
    // Prefer big blobs near the horizontal centre.
    const double dx = std::abs(mo.m10 / mo.m00 - cx) / diag;
    const double score = mo.m00 * (1.0 - dx);
    if (score > best_score) best_score = score, best = int(i);
  }
  if (num_blobs) *num_blobs = 0;
  if (best < 0) return {};
  if (num_blobs)
    for (double a : areas) *num_blobs += a >= 0.5 * areas[best];
  cv::Mat filled = cv::Mat::zeros(m.size(), CV_8U);
  cv::drawContours(filled, contours, best, cv::Scalar(255), cv::FILLED);
  return filled;
}

YCrCb to_ycrcb(const cv::Vec3b& p) {
  const double y = 0.299 * p[2] + 0.587 * p[1] + 0.114 * p[0];
  const auto u8 = [](double v) { return cv::saturate_cast<uchar>(v); };
  return {u8(y), u8((p[2] - y) * 0.713 + 128), u8((p[0] - y) * 0.564 + 128)};
}

float skin_likelihood(const YCrCb& s) {
  // Distance from the centre of the classic skin box Cr 133..173, Cb 77..127, soft edges.
  const float dcr = std::max(0.f, std::abs(s.cr - 153.f) - 20.f);
  const float dcb = std::max(0.f, std::abs(s.cb - 102.f) - 25.f);
  const float lum = s.luma < 40 ? (s.luma - 20.f) / 20.f : 1.f;
  return std::clamp(1.f - (dcr + dcb) / 12.f, 0.f, 1.f) * std::clamp(lum, 0.f, 1.f);
}

cv::Mat skin_probability(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("skin_probability: expected 8-bit BGR image");
  cv::Mat ycc;
  cv::cvtColor(bgr, ycc, cv::COLOR_BGR2YCrCb);
  cv::Mat p(bgr.size(), CV_32F);
  for (int r = 0; r < ycc.rows; ++r) {
    const cv::Vec3b* s = ycc.ptr<cv::Vec3b>(r);
    float* o = p.ptr<float>(r);
    for (int c = 0; c < ycc.cols; ++c) o[c] = skin_likelihood({s[c][0], s[c][1], s[c][2]});
  }
  return p;
}

}  // namespace orthoface::vision
