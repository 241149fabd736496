// B-spline fitting and evaluation (seed 004 §4 profile models).
#include "vision/bspline.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace ov = orthoface::vision;

TEST(BSpline, FitReproducesALine) {
  std::vector<cv::Point2d> pts;
  for (int i = 0; i <= 50; ++i) pts.emplace_back(10 + 2.0 * i, 5 + 1.0 * i);
  const ov::BSpline2d s = ov::fit_bspline(pts, ov::chord_parameters(pts), {}, 8, 0.0);
  for (double t : {0.0, 0.3, 0.77, 1.0}) {
    const cv::Point2d p = ov::bspline_point(s, t);
    EXPECT_NEAR(p.x, 10 + 100 * t, 1e-3);
    EXPECT_NEAR(p.y, 5 + 50 * t, 1e-3);
  }
}

TEST(BSpline, RejectsBadInput) {
  EXPECT_THROW(ov::bspline_point(ov::BSpline2d{{{0, 0}, {1, 1}}}, 0.5), std::invalid_argument);
  EXPECT_THROW(ov::fit_bspline({{0, 0}}, {0.0}, {}, 3, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::fit_bspline({{0, 0}, {1, 1}}, {0.0}, {}, 4, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::chord_parameters({}), std::invalid_argument);
}

TEST(BSpline, DegenerateAllPointsEqual) {
  const std::vector<cv::Point2d> pts(10, cv::Point2d(3, 4));
  const auto t = ov::chord_parameters(pts);  // zero length: uniform parameters
  EXPECT_DOUBLE_EQ(t.back(), 1.0);
  const ov::BSpline2d s = ov::fit_bspline(pts, t, {}, 4, 0.1);
  EXPECT_NEAR(ov::bspline_point(s, 0.5).x, 3, 1e-6);
}
