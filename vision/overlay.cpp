#include "vision/overlay.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/image_prep.h"

namespace orthoface::vision {

namespace {

cv::Point2d in(cv::Point2d p) { return p - cv::Point2d(0.5, 0.5); }  // capture px -> index

void draw_features(cv::Mat& m, const ViewObservation& v) {
  const double fs = std::max(0.3, m.rows / 1400.0);
  for (const auto& [name, f] : v.features) {
    cv::Scalar col = f.mirrored ? cv::Scalar(255, 0, 255)
                     : f.method.find("position-model") != std::string::npos
                         ? cv::Scalar(0, 255, 255)
                         : cv::Scalar(0, 0, 255);
    cv::circle(m, in(f.px), std::max(2, m.rows / 250), col, cv::FILLED, cv::LINE_AA);
    cv::putText(m, name, in(f.px) + cv::Point2d(4, -3), cv::FONT_HERSHEY_SIMPLEX, fs,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
}

void draw_polyline(cv::Mat& m, const std::vector<cv::Point2d>& pts, double max_jump) {
  for (size_t i = 1; i < pts.size(); ++i)
    if (cv::norm(pts[i] - pts[i - 1]) < max_jump)
      cv::line(m, in(pts[i - 1]), in(pts[i]), cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat overlay_front(const cv::Mat& front, const FaceObservation& obs) {
  cv::Mat m = to_bgr8(front, "overlay front image");
  draw_polyline(m, obs.front.boundary, 6.0);
  if (obs.centre_confidence > 0) {
    const double t = std::tan(obs.roll_rad);
    const cv::Point2d a(obs.centre_x_px + t * (0 - obs.centre_y_px), 0);
    const cv::Point2d b(obs.centre_x_px + t * (m.rows - obs.centre_y_px), m.rows);
    cv::line(m, in(a), in(b), cv::Scalar(255, 255, 0), 1, cv::LINE_AA);
  }
  draw_features(m, obs.front);
  return m;
}

cv::Mat overlay_side(const cv::Mat& side, const FaceObservation& obs) {
  cv::Mat m = to_bgr8(side, "overlay side image");
  draw_polyline(m, obs.side.boundary, 6.0);
  draw_features(m, obs.side);
  return m;
}

cv::Mat overlay_pair(const cv::Mat& front, const cv::Mat& side, const FaceObservation& obs) {
  cv::Mat a = overlay_front(front, obs), b = overlay_side(side, obs);
  if (b.rows != a.rows) cv::resize(b, b, cv::Size(std::max(1, b.cols * a.rows / b.rows), a.rows));
  cv::Mat out;
  cv::hconcat(a, b, out);
  return out;
}

}  // namespace orthoface::vision
