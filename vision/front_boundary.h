#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/profile_fit.h"

namespace orthoface::vision {

struct FrontBoundaryOptions {
  double control_spacing_px = 10.0;  // arc length between the profile model's control points
  ProfileFitOptions fit;             // iterative fit; num_control/samples/polarity set per side
  void check() const;                // throws std::invalid_argument on out-of-range values
};

// Front-view extremal boundary (seed 004 §4) in index coordinates (pixel centre = (c, r)):
// one point per row from top_row to bottom_row on each side.
struct FrontBoundary {
  std::vector<cv::Point2d> left, right;  // image-left side and image-right side, top to bottom
  int top_row = -1, bottom_row = -1;
  double confidence = 0.0;     // share of the curve backed by edges
  double head_width_px = 0.0;  // widest row of the blob (ears included)
  std::vector<std::string> warnings;
};

// Silhouette of the head blob `mask` (CV_8U) refined on the edges of `prob` (CV_32F) by the
// B-spline profile model, from the crown down to `bottom_row` (< 0: estimated from the blob as
// crown + 1.45 x width). An empty mask gives an empty boundary with a warning. Throws
// std::invalid_argument when sizes or types differ.
FrontBoundary front_boundary(const cv::Mat& prob, const cv::Mat& mask, int bottom_row,
                             const FrontBoundaryOptions& options = {});

// x of a boundary side at row y (linear between rows; clamped at the ends); NaN when empty.
double boundary_x(const std::vector<cv::Point2d>& side, double y);

}  // namespace orthoface::vision
