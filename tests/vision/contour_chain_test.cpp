// Head widths along the silhouette contour.
#include "vision/contour_chain.h"

#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace ov = orthoface::vision;

TEST(ContourChain, HeadWidthIgnoresTheShoulders) {
  cv::Mat mask(400, 400, CV_8U, cv::Scalar(0));
  cv::circle(mask, {200, 100}, 50, cv::Scalar(255), cv::FILLED);  // head, 101 px wide
  mask(cv::Rect(185, 140, 31, 100)).setTo(255);                   // neck
  mask(cv::Rect(40, 240, 320, 160)).setTo(255);                   // shoulders
  EXPECT_NEAR(ov::head_width(ov::row_extent(mask)), 101, 1);
  EXPECT_EQ(ov::head_width(ov::row_extent(cv::Mat(10, 10, CV_8U, cv::Scalar(0)))), 0.0);
  EXPECT_THROW(ov::row_extent(cv::Mat()), std::invalid_argument);
}

TEST(ContourChain, FrontHeadWidthStopsAtAHood) {
  // A head whose blob runs straight into a hood widening from its cheeks (no neck in between):
  // the plain walk takes the hood's width, the front-view walk stops where the widening starts.
  cv::Mat mask(500, 500, CV_8U, cv::Scalar(0));
  cv::ellipse(mask, {250, 120}, {60, 80}, 0, 0, 360, cv::Scalar(255), cv::FILLED);  // 121 px wide
  std::vector<cv::Point> hood = {{190, 130}, {310, 130}, {480, 330}, {20, 330}};
  cv::fillConvexPoly(mask, hood, cv::Scalar(255));
  mask(cv::Rect(20, 330, 461, 170)).setTo(255);
  EXPECT_GT(ov::head_width(ov::row_extent(mask)), 200);
  EXPECT_NEAR(ov::head_width(ov::row_extent(mask), true), 121, 6);
  EXPECT_EQ(ov::head_width(ov::row_extent(cv::Mat(10, 10, CV_8U, cv::Scalar(0))), true), 0.0);
}
