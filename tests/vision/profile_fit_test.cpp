// The iterative fit of a B-spline profile model to edges.
#include "vision/profile_fit.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace ov = orthoface::vision;

// A filled disc of radius 80 px: the profile model started 5 px off must land on its edge.
TEST(ProfileFit, ConvergesToDiscEdge) {
  cv::Mat img(300, 300, CV_32F, cv::Scalar(0));
  cv::circle(img, {150, 150}, 80, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  std::vector<cv::Point2d> init;
  for (int i = 0; i <= 40; ++i) {
    const double a = M_PI * (0.2 + 0.6 * i / 40.0);  // an arc on the disc's lower half
    init.emplace_back(150 + 85 * std::cos(a), 150 + 85 * std::sin(a));
  }
  const ov::BSpline2d s0 = ov::fit_bspline(init, ov::chord_parameters(init), {}, 10, 0.01);
  ov::ProfileFitOptions o;
  o.num_control = 10;
  const ov::ProfileFit fit = ov::fit_profile_to_edges(s0, ov::edge_image(img, {0.7, 0.1}), o);
  EXPECT_GT(fit.support, 0.95);
  const auto pts = ov::bspline_samples(fit.spline, 30);
  for (size_t i = 2; i + 2 < pts.size(); ++i)  // the clamped ends see half a search window
    EXPECT_NEAR(std::hypot(pts[i].x - 150, pts[i].y - 150), 80.0, 0.3);
}

TEST(ProfileFit, NoEdgesKeepsTheModel) {
  const cv::Mat flat(100, 100, CV_32F, cv::Scalar(0.5));
  const ov::BSpline2d s0{{{10, 10}, {30, 40}, {50, 60}, {70, 90}}};
  const ov::ProfileFit fit = ov::fit_profile_to_edges(s0, ov::edge_image(flat), {});
  EXPECT_EQ(fit.support, 0.0);
  EXPECT_NEAR(ov::bspline_point(fit.spline, 0.5).x, ov::bspline_point(s0, 0.5).x, 1.0);
  ov::ProfileFitOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(ov::fit_profile_to_edges(s0, ov::edge_image(flat), bad), std::invalid_argument);
}
