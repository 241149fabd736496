#include "render/equalize.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace orthoface::render::detail {

Eigen::Vector2d undistorted_pixel(const capture::CameraModel& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d pc = c.cam_from_head * p;
  const Eigen::Vector2d xy = c.projection == capture::Projection::Orthographic
                                 ? Eigen::Vector2d(pc.x(), pc.y())
                                 : Eigen::Vector2d(pc.x() / pc.z(), pc.y() / pc.z());
  return {c.cx + c.fx * xy.x(), c.cy + c.fy * xy.y()};
}

double facing(const capture::CameraModel& c, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  if (c.projection == capture::Projection::Orthographic) return n.dot(-capture::view_direction(c));
  const Eigen::Vector3d centre = c.cam_from_head.inverse().translation();
  return n.dot((centre - p).normalized());
}

bool source_sees(const capture::CameraModel& c, const cv::Mat& depth, const Eigen::Vector3d& p,
                 double cosine, double tolerance_mm) {
  if (!(cosine > 0)) return false;
  const double z = capture::depth(c, p);
  if (c.projection == capture::Projection::Perspective && !(z > 0)) return false;
  const Eigen::Vector2d u = undistorted_pixel(c, p);
  const int col = int(std::floor(u.x())), row = int(std::floor(u.y()));
  if (col < 0 || row < 0 || col >= depth.cols || row >= depth.rows) return false;
  const double px_mm = (c.projection == capture::Projection::Perspective ? z : 1.0) / c.fx;
  const double tol = tolerance_mm + 1.5 * px_mm / std::max(cosine, 0.2);  // as in the shader
  return z <= depth.at<float>(row, col) + tol;
}

cv::Vec3d bilinear(const cv::Mat& bgr, const Eigen::Vector2d& uv) {
  const double x = std::clamp(uv.x() - 0.5, 0.0, bgr.cols - 1.0);
  const double y = std::clamp(uv.y() - 0.5, 0.0, bgr.rows - 1.0);
  const int x0 = int(x), y0 = int(y);
  const int x1 = std::min(x0 + 1, bgr.cols - 1), y1 = std::min(y0 + 1, bgr.rows - 1);
  const double fx = x - x0, fy = y - y0;
  cv::Vec3d out;
  for (int k = 0; k < 3; ++k)
    out[k] =
        (1 - fy) * ((1 - fx) * bgr.at<cv::Vec3b>(y0, x0)[k] + fx * bgr.at<cv::Vec3b>(y0, x1)[k]) +
        fy * ((1 - fx) * bgr.at<cv::Vec3b>(y1, x0)[k] + fx * bgr.at<cv::Vec3b>(y1, x1)[k]);
  return out;
}

namespace {

// The Lab channel k's contrast of `source` scaled to the front's (bounded).
double channel_gain(const ColourMatch& m, int source, int k) {
  const double s = m.stddev[source][k];
  return s > 1e-6 ? std::clamp(m.stddev[0][k] / s, 0.67, 1.5) : 1.0;
}

void lab_stats(const std::vector<cv::Vec3f>& bgr01, cv::Vec3d& mean, cv::Vec3d& stddev) {
  cv::Mat lab;
  cv::cvtColor(cv::Mat(bgr01).reshape(3, int(bgr01.size())), lab, cv::COLOR_BGR2Lab);
  cv::Scalar m, s;
  cv::meanStdDev(lab, m, s);
  mean = cv::Vec3d(m[0], m[1], m[2]);
  stddev = cv::Vec3d(s[0], s[1], s[2]);
}

}  // namespace

ColourMatch colour_match(const std::vector<Eigen::Vector3d>& vertices,
                         const std::vector<Eigen::Vector3d>& normals,
                         const capture::RigCalibration& rig, const std::array<cv::Mat, 2>& depth,
                         const std::array<cv::Mat, 2>& photos) {
  const capture::CameraModel* cams[2] = {&rig.front, &rig.side};
  std::array<std::vector<cv::Vec3f>, 2> overlap;
  std::vector<cv::Vec3b> front_seen;  // raw front colours of the surface it sees well
  for (size_t v = 0; v < vertices.size(); ++v) {
    const Eigen::Vector3d& p = vertices[v];
    double cosine[2];
    bool sees[2];
    for (int i = 0; i < 2; ++i) {
      cosine[i] = facing(*cams[i], p, normals[v]);
      sees[i] = source_sees(*cams[i], depth[i], p, cosine[i], 1.0);
    }
    if (sees[0] && cosine[0] > 0.5) {
      const cv::Vec3d c = bilinear(photos[0], capture::project(*cams[0], p));
      front_seen.push_back(cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                     cv::saturate_cast<uchar>(c[2])));
    }
    if (!(sees[0] && sees[1] && cosine[0] > 0.35 && cosine[1] > 0.35)) continue;
    for (int i = 0; i < 2; ++i)
      overlap[i].push_back(cv::Vec3f(bilinear(photos[i], capture::project(*cams[i], p)) / 255.0));
  }
  ColourMatch m;
  m.samples = int(overlap[0].size());
  if (m.samples > 0)
    for (int i = 0; i < 2; ++i) lab_stats(overlap[i], m.mean[i], m.stddev[i]);
  // The side's mean is then replaced by the side value that the median of the pairs' differences
  // maps onto the front's mean: the pairs are the same surface point in both photos, and a pair
  // that is not (the adapted mesh a little off: hair, ear or background in one photo) moves a
  // mean but not the median. On the sim heads (two identical cameras) matching the means shifted
  // the side photo by the contaminated pairs (whole head at 45 deg: 27.5 dB against 28.0).
  if (m.samples > 0) {
    cv::Mat lab[2];
    for (int i = 0; i < 2; ++i)
      cv::cvtColor(cv::Mat(overlap[i]).reshape(3, m.samples), lab[i], cv::COLOR_BGR2Lab);
    std::vector<float> d(size_t(m.samples));
    for (int k = 0; k < 3; ++k) {
      const double gain = channel_gain(m, 1, k);
      for (int j = 0; j < m.samples; ++j)
        d[size_t(j)] = float(lab[0].at<cv::Vec3f>(j)[k] - gain * lab[1].at<cv::Vec3f>(j)[k]);
      std::nth_element(d.begin(), d.begin() + m.samples / 2, d.end());
      m.mean[1][k] = (m.mean[0][k] - d[size_t(m.samples / 2)]) / gain;
    }
  }
  if (!front_seen.empty()) {  // equalise only the sampled colours, not the whole photo
    const cv::Scalar mean = cv::mean(equalized(cv::Mat(front_seen), m, 0));
    m.fill = cv::Vec3b(cv::saturate_cast<uchar>(mean[0]), cv::saturate_cast<uchar>(mean[1]),
                       cv::saturate_cast<uchar>(mean[2]));
  }
  return m;
}

namespace {

// In place on CV_32FC3 BGR (0..1): Lab of each pixel of the side photo mapped to the front
// photo's statistics. The front photo is the reference and stays as it is: the view at the front
// camera gives it back, and a composited frame meets the live front camera's colours.
void map_lab(cv::Mat& bgr01, const ColourMatch& m, int source) {
  if (source == 0) return;
  cv::Mat lab;
  cv::cvtColor(bgr01, lab, cv::COLOR_BGR2Lab);
  std::vector<cv::Mat> ch;
  cv::split(lab, ch);
  for (int k = 0; k < 3; ++k) {
    const double gain = channel_gain(m, source, k);
    ch[k].convertTo(ch[k], CV_32F, gain, m.mean[0][k] - gain * m.mean[source][k]);
  }
  // Lightness below the skin's: the line through the skin's statistics takes dark hair below
  // black when gain x the side's skin mean exceeds the front's (a side photo lit brighter than
  // the front) and lifts black to grey when it falls short (a gain below 1 with skins alike: a
  // real pair's black hair came out L 33). The ray from black through the skin's mean lightness
  // keeps black black, scales the darks as a change of exposure does, and meets the line at that
  // mean.
  const double sm = m.mean[source][0], tm = m.mean[0][0];
  if (sm > 1e-6) {
    cv::Mat source_l;
    cv::extractChannel(lab, source_l, 0);
    const cv::Mat ray = source_l * (tm / sm);
    ray.copyTo(ch[0], source_l < sm);
  }
  cv::merge(ch, lab);
  cv::cvtColor(lab, bgr01, cv::COLOR_Lab2BGR);
}

}  // namespace

cv::Mat equalized(const cv::Mat& photo, const ColourMatch& m, int source) {
  if (m.samples < kMinSamples) return photo.clone();
  cv::Mat bgr01;
  photo.convertTo(bgr01, CV_32F, 1.0 / 255);
  map_lab(bgr01, m, source);
  cv::Mat out;
  bgr01.convertTo(out, CV_8U, 255.0);
  return out;
}

cv::Mat equalize_grid(const ColourMatch& m, int source, int n) {
  if (n < 2 || n > 256)
    throw std::invalid_argument("equalize grid: size must be in 2..256, got " + std::to_string(n));
  cv::Mat grid(1, n * n * n, CV_32FC3);
  auto* out = grid.ptr<cv::Vec3f>();
  const float step = 1.0f / float(n - 1);
  for (int b = 0; b < n; ++b)
    for (int g = 0; g < n; ++g)
      for (int r = 0; r < n; ++r) *out++ = cv::Vec3f(b * step, g * step, r * step);
  if (m.samples >= kMinSamples) map_lab(grid, m, source);
  return grid;
}

}  // namespace orthoface::render::detail
