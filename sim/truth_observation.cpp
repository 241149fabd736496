#include "sim/truth_observation.h"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/landmarks.h"

namespace orthoface::sim {
namespace {

// First (from_left) or last masked column of `row`, or -1 when the row is empty.
int edge_column(const cv::Mat& mask, int row, bool from_left) {
  const uchar* p = mask.ptr<uchar>(row);
  if (from_left) {
    for (int c = 0; c < mask.cols; ++c)
      if (p[c]) return c;
  } else {
    for (int c = mask.cols - 1; c >= 0; --c)
      if (p[c]) return c;
  }
  return -1;
}

void check_mask(const cv::Mat& mask, const char* what) {
  if (mask.empty() || mask.type() != CV_8U)
    throw std::invalid_argument(std::string("truth_observation: ") + what +
                                " mask must be non-empty CV_8U");
  if (cv::countNonZero(mask) == 0)
    throw std::invalid_argument(std::string("truth_observation: ") + what + " mask is empty");
}

// Outline points at pixel edges (column c's outer edge), one per row.
std::vector<cv::Point2d> outline(const cv::Mat& mask, bool from_left) {
  std::vector<cv::Point2d> pts;
  for (int r = 0; r < mask.rows; ++r) {
    const int c = edge_column(mask, r, from_left);
    if (c >= 0) pts.emplace_back(from_left ? c : c + 1.0, r + 0.5);
  }
  return pts;
}

}  // namespace

vision::FaceObservation truth_observation(const Capture& capture) {
  check_mask(capture.front_mask, "front");
  check_mask(capture.side_mask, "side");
  vision::FaceObservation o;
  o.front.width = capture.front_mask.cols;
  o.front.height = capture.front_mask.rows;
  o.side.width = capture.side_mask.cols;
  o.side.height = capture.side_mask.rows;
  o.front.boundary = outline(capture.front_mask, true);
  const auto right = outline(capture.front_mask, false);
  o.front.boundary.insert(o.front.boundary.end(), right.begin(), right.end());
  o.side.boundary = outline(capture.side_mask, true);
  o.front.boundary_confidence = o.side.boundary_confidence = 1.0;
  // Centre line x = a + b (y - y0) fitted through the visible midline landmarks.
  std::vector<cv::Point2d> mid;
  for (const auto& [name, t] : capture.landmarks) {
    if (t.visible_front)
      o.front.features[name] = {{t.front_px.x(), t.front_px.y()}, 1.0, "truth", false};
    if (t.visible_side)
      o.side.features[name] = {{t.side_px.x(), t.side_px.y()}, 1.0, "truth", false};
    if (t.visible_front && vision::is_landmark_name(name) && vision::mirrored_name(name) == name)
      mid.emplace_back(t.front_px.x(), t.front_px.y());
  }
  if (mid.size() >= 2) {
    cv::Vec4d line;
    cv::fitLine(mid, line, cv::DIST_L2, 0, 0.01, 0.01);
    if (line[1] < 0) line[0] = -line[0], line[1] = -line[1];
    o.centre_x_px = line[2];
    o.centre_y_px = line[3];
    o.roll_rad = std::atan2(line[0], line[1]);
    o.centre_confidence = 1.0;
  } else {
    o.centre_x_px = o.front.width / 2.0;
    o.centre_y_px = o.front.height / 2.0;
    o.warnings.push_back("truth_observation: fewer than 2 midline landmarks visible");
  }
  return o;
}

}  // namespace orthoface::sim
