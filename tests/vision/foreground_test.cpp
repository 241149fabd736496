// The subject mask: background model, skin colour, the central blob.
#include "vision/foreground.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace ov = orthoface::vision;

TEST(Foreground, BorderModelFindsACentralDisc) {
  cv::Mat img(200, 200, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::circle(img, {100, 110}, 50, cv::Scalar(90, 120, 200), cv::FILLED);
  const cv::Mat m = ov::head_mask(ov::foreground_probability(img, cv::Mat()));
  ASSERT_FALSE(m.empty());
  EXPECT_NEAR(cv::countNonZero(m), M_PI * 50 * 50, 300);
  // Degenerate: a blank image has no head; a background frame of another size is refused.
  EXPECT_TRUE(ov::head_mask(ov::foreground_probability(
                                cv::Mat(200, 200, CV_8UC3, cv::Scalar(9, 9, 9)), cv::Mat()))
                  .empty());
  EXPECT_THROW(ov::foreground_probability(img, cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(ov::foreground_probability(cv::Mat(), cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ov::head_mask(cv::Mat(10, 10, CV_8U)), std::invalid_argument);
}

TEST(Foreground, PixelYCrCbAndSkinMatchTheImageVersions) {
  cv::Mat img(16, 16, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  img.at<cv::Vec3b>(0, 0) = {0, 0, 0};
  img.at<cv::Vec3b>(0, 1) = {255, 255, 255};
  img.at<cv::Vec3b>(0, 2) = {90, 120, 200};  // a skin tone
  cv::Mat ycc;
  cv::cvtColor(img, ycc, cv::COLOR_BGR2YCrCb);
  const cv::Mat skin = ov::skin_probability(img);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) {
      const ov::YCrCb y = ov::to_ycrcb(img.at<cv::Vec3b>(r, c));
      const cv::Vec3b ref = ycc.at<cv::Vec3b>(r, c);
      EXPECT_NEAR(y.luma, ref[0], 1);
      EXPECT_NEAR(y.cr, ref[1], 1);
      EXPECT_NEAR(y.cb, ref[2], 1);
      EXPECT_NEAR(ov::skin_likelihood({ref[0], ref[1], ref[2]}), skin.at<float>(r, c), 1e-6);
    }
  EXPECT_GT(skin.at<float>(0, 2), 0.9f);
  EXPECT_EQ(skin.at<float>(0, 0), 0.f);  // black is no skin
  EXPECT_THROW(ov::skin_probability(cv::Mat(4, 4, CV_8U)), std::invalid_argument);
}

TEST(Foreground, TwoBlobsCountedCentralOneChosen) {
  cv::Mat img(200, 300, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::circle(img, {150, 110}, 40, cv::Scalar(90, 120, 200), cv::FILLED);  // central
  cv::circle(img, {235, 110}, 35, cv::Scalar(90, 120, 200), cv::FILLED);  // off-centre
  cv::circle(img, {150, 110}, 8, cv::Scalar(200, 200, 200), cv::FILLED);  // a hole
  int blobs = 0;
  const cv::Mat m = ov::head_mask(ov::foreground_probability(img, cv::Mat()), {}, &blobs);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(blobs, 2);
  EXPECT_EQ(m.at<uchar>(110, 150), 255);  // hole filled
  EXPECT_EQ(m.at<uchar>(110, 235), 0);
  EXPECT_NEAR(cv::countNonZero(m), M_PI * 40 * 40, 250);
}

// A colour's count stays in its bin and reaches each of its 26 neighbours (only those inside the
// cube at a corner) times the weight, nothing further.
TEST(Foreground, SpreadToNeighboursReachesOneBinEitherWay) {
  std::vector<float> counts(size_t(ov::kColourBins), 0.f);
  const cv::Vec3b grey(128, 128, 128), corner(0, 0, 0);
  counts[size_t(ov::colour_bin(grey))] = 8;
  counts[size_t(ov::colour_bin(corner))] = 4;
  const std::vector<float> s = ov::spread_to_neighbours(counts, 0.25f);
  EXPECT_FLOAT_EQ(s[size_t(ov::colour_bin(grey))], 8.f);
  EXPECT_FLOAT_EQ(s[size_t(ov::colour_bin(cv::Vec3b(144, 112, 128)))],
                  2.f);  // one bin off each way
  EXPECT_FLOAT_EQ(s[size_t(ov::colour_bin(cv::Vec3b(160, 128, 128)))], 0.f);  // two bins off
  EXPECT_FLOAT_EQ(s[size_t(ov::colour_bin(cv::Vec3b(16, 16, 16)))], 1.f);
  double total = 0;
  for (float v : s) total += v;
  EXPECT_NEAR(total, 8 + 26 * 2 + 4 + 7 * 1, 1e-4);  // the corner has 7 neighbours
  EXPECT_THROW(ov::spread_to_neighbours(std::vector<float>(10, 1.f), 1.f), std::invalid_argument);
}
