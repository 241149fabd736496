#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Open cubic B-spline curve in the image plane with a clamped uniform knot vector: it starts at
// the first control point and ends at the last (seed 004 §4 profile models).
struct BSpline2d {
  std::vector<cv::Point2d> control;  // at least 4
};

// Point at parameter t in [0, 1] (clamped). Throws std::invalid_argument with < 4 control points.
cv::Point2d bspline_point(const BSpline2d& spline, double t);

// Unit tangent (d point / dt normalised) at t; (0,0) where the derivative vanishes.
cv::Point2d bspline_tangent(const BSpline2d& spline, double t);

// `count` points at uniform t from 0 to 1 (count >= 2).
std::vector<cv::Point2d> bspline_samples(const BSpline2d& spline, int count);

// Least-squares spline with `num_control` control points through `points` at parameters `t`
// (same length, in [0, 1]) with weights `w` (empty = all 1), regularised by
// `smoothness` * sum |second difference of control points|^2. Throws std::invalid_argument on
// mismatched sizes, num_control < 4 or fewer than 2 points with positive weight.
BSpline2d fit_bspline(const std::vector<cv::Point2d>& points, const std::vector<double>& t,
                      const std::vector<double>& w, int num_control, double smoothness);

// Chord-length parameters of a polyline, in [0, 1]. Throws std::invalid_argument when empty.
std::vector<double> chord_parameters(const std::vector<cv::Point2d>& points);

}  // namespace orthoface::vision
