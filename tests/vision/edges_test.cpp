// Edge images and the colour-step snap.
#include "vision/edges.h"

#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace ov = orthoface::vision;

TEST(EdgeImage, StepEdgeAndBadInput) {
  cv::Mat img(40, 40, CV_8U, cv::Scalar(50));
  img(cv::Rect(20, 0, 20, 40)).setTo(200);
  const ov::EdgeImage e = ov::edge_image(img);
  EXPECT_GT(e.edges.at<uchar>(20, 19) + e.edges.at<uchar>(20, 20), 0);
  EXPECT_EQ(e.edges.at<uchar>(20, 5), 0);
  EXPECT_THROW(ov::edge_image(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ov::edge_image(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  const ov::EdgeImage flat = ov::edge_image(cv::Mat(40, 40, CV_8U, cv::Scalar(7)));
  EXPECT_EQ(cv::countNonZero(flat.edges), 0);
}

TEST(SnapToColourStep, FindsThePixelBorderOfAStepAndKeepsWeakOnes) {
  cv::Mat img(30, 40, CV_8UC3, cv::Scalar(200, 200, 200));
  img(cv::Rect(20, 0, 20, 30)).setTo(cv::Scalar(90, 120, 170));  // step between columns 19 and 20
  const std::vector<cv::Point2d> pts = {{18.0, 10.0}, {21.2, 12.0}, {5.0, 15.0}};
  const std::vector<cv::Point2d> dirs(3, {1.0, 0.0});
  const auto out = ov::snap_to_colour_step(img, pts, dirs, 2.0, 20);
  EXPECT_NEAR(out[0].x, 19.5, 0.1);  // the border between the two pixel centres
  EXPECT_NEAR(out[1].x, 19.5, 0.1);
  EXPECT_DOUBLE_EQ(out[0].y, 10.0);  // moved along the direction only
  EXPECT_EQ(out[2], pts[2]);         // no step within range: unchanged
  // A diagonal direction finds the same border (the point moves along it).
  const auto diag = ov::snap_to_colour_step(img, {{18.0, 10.0}}, {{1.0, 1.0}}, 3.0, 20);
  EXPECT_NEAR(diag[0].x, 19.5, 0.1);
  EXPECT_NEAR(diag[0].y, 11.5, 0.1);
  // A step weaker than min_step leaves the point.
  EXPECT_EQ(ov::snap_to_colour_step(img, pts, dirs, 2.0, 1000)[0], pts[0]);
  EXPECT_TRUE(ov::snap_to_colour_step(img, {}, {}, 2.0, 20).empty());
  EXPECT_THROW(ov::snap_to_colour_step(cv::Mat(), pts, dirs, 2.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(cv::Mat(30, 40, CV_8U), pts, dirs, 2.0, 20),
               std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, {{1.0, 0.0}}, 2.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, dirs, 0.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, dirs, 2.0, -1), std::invalid_argument);
}

TEST(EdgeImage, RegionMatchesTheWholeImageInsideAndIsZeroOutside) {
  cv::Mat img(60, 80, CV_32F, cv::Scalar(0));
  cv::circle(img, {40, 30}, 15, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const ov::EdgeImage whole = ov::edge_image(img, {0.7, 0.1});
  const cv::Rect roi(15, 5, 50, 50);  // the disc plus 10 px
  const ov::EdgeImage part = ov::edge_image(img, {0.7, 0.1}, roi);
  ASSERT_EQ(part.gx.size(), roi.size());
  EXPECT_EQ(part.origin, roi.tl());
  EXPECT_LT(cv::norm(whole.gx(roi), part.gx, cv::NORM_INF), 1e-5);
  EXPECT_LT(cv::norm(whole.gy(roi), part.gy, cv::NORM_INF), 1e-5);
  EXPECT_NEAR(part.threshold, whole.threshold, 0.05 * whole.threshold);  // 1-in-4 sampling
  EXPECT_EQ(cv::countNonZero(part.edges != whole.edges(roi)), 0);
  // A region clipped by the image border keeps its in-image part.
  EXPECT_EQ(ov::edge_image(img, {}, cv::Rect(-5, -5, 20, 20)).gx.size(), cv::Size(15, 15));
  EXPECT_THROW(ov::edge_image(img, {}, cv::Rect(100, 100, 5, 5)), std::invalid_argument);
  EXPECT_THROW(ov::edge_image(cv::Mat(), {}, roi), std::invalid_argument);
}
