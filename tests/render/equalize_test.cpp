// Colour equalisation of the side photo to the front's (render/equalize.h).
#include "render/equalize.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace orthoface::render::detail {
namespace {

// Lightness (L, 0..100) of a grey BGR level.
double lightness(int grey) {
  cv::Mat px(1, 1, CV_32FC3, cv::Scalar::all(grey / 255.0)), lab;
  cv::cvtColor(px, lab, cv::COLOR_BGR2Lab);
  return lab.at<cv::Vec3f>(0, 0)[0];
}

// A side photo lit brighter than the front: its skin's mean lightness 70 against the front's 50.
ColourMatch brighter_side() {
  ColourMatch m;
  m.samples = 100;
  m.mean = {cv::Vec3d(50, 10, 15), cv::Vec3d(70, 10, 15)};
  m.stddev = {cv::Vec3d(10, 4, 4), cv::Vec3d(8, 4, 4)};
  return m;
}

TEST(Equalized, KeepsDarkHairDarkButNotBlack) {
  const ColourMatch m = brighter_side();
  // Grey levels from dark hair to bright skin, one pixel each.
  const int levels[] = {12, 30, 50, 80, 200, 230};
  cv::Mat side(1, 6, CV_8UC3);
  for (int i = 0; i < 6; ++i) side.at<cv::Vec3b>(0, i) = cv::Vec3b::all(uchar(levels[i]));
  const cv::Mat out = equalized(side, m, 1);
  int previous = -1;
  for (int i = 0; i < 6; ++i) {
    const cv::Vec3b c = out.at<cv::Vec3b>(0, i);
    const int sum = c[0] + c[1] + c[2];
    // The line through the skin's statistics takes L = 20 (level 50) to 50 + 1.25 (20 - 70) < 0:
    // pure black. Every level stays lit and in order.
    EXPECT_GT(sum, 0) << "level " << levels[i];
    EXPECT_GT(sum, previous) << "level " << levels[i];
    previous = sum;
  }
  // At the skin's mean lightness and above, the mapping is the statistics' line.
  const int skin = 200;
  const double l = lightness(skin);
  ASSERT_GT(l, 70);
  cv::Mat lab;
  cv::Mat px;
  out.colRange(4, 5).convertTo(px, CV_32F, 1.0 / 255);
  cv::cvtColor(px, lab, cv::COLOR_BGR2Lab);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 0)[0], 50 + 1.25 * (l - 70), 1.5);
}

// The skin spreads less in the front photo than in the side (gain 0.67): the statistics' line
// takes black hair to L 50 - 0.67 * 60 = 10 and near-black to grey; the darks must stay as dark
// as an exposure change makes them (FRMDB 028's black hair came out L 33).
TEST(Equalized, KeepsBlackHairBlackWhenTheGainIsBelowOne) {
  ColourMatch m;
  m.samples = 100;
  m.mean = {cv::Vec3d(60, 10, 15), cv::Vec3d(60, 10, 15)};
  m.stddev = {cv::Vec3d(8, 4, 4), cv::Vec3d(12, 4, 4)};
  const int levels[] = {0, 10, 25, 40};
  cv::Mat side(1, 4, CV_8UC3);
  for (int i = 0; i < 4; ++i) side.at<cv::Vec3b>(0, i) = cv::Vec3b::all(uchar(levels[i]));
  const cv::Mat out = equalized(side, m, 1);
  for (int i = 0; i < 4; ++i) {
    const cv::Vec3b c = out.at<cv::Vec3b>(0, i);
    // Same skin mean in both photos: the ray from black is the identity below it.
    EXPECT_NEAR((c[0] + c[1] + c[2]) / 3.0, levels[i], 2.0) << "level " << levels[i];
  }
}

TEST(Equalized, TheFrontPhotoAndTooFewSamplesAreLeftAsTheyAre) {
  ColourMatch m = brighter_side();
  const cv::Mat photo(4, 4, CV_8UC3, cv::Scalar(20, 40, 60));
  EXPECT_EQ(cv::norm(equalized(photo, m, 0), photo, cv::NORM_INF), 0.0);
  m.samples = kMinSamples - 1;
  EXPECT_EQ(cv::norm(equalized(photo, m, 1), photo, cv::NORM_INF), 0.0);
}

TEST(EqualizeGrid, MatchesThePhotoMappingAndRefusesBadSizes) {
  const ColourMatch m = brighter_side();
  const int n = 5;
  const cv::Mat grid = equalize_grid(m, 1, n);
  ASSERT_EQ(grid.cols, n * n * n);
  // The grid's darkest grey entry above black is the photo mapping of that grey.
  const int b = 1, g = 1, r = 1;  // (64, 64, 64)
  const cv::Vec3f entry = grid.at<cv::Vec3f>(0, (b * n + g) * n + r);
  const cv::Mat grey(1, 1, CV_8UC3, cv::Scalar::all(255.0 / (n - 1)));
  const cv::Vec3b mapped = equalized(grey, m, 1).at<cv::Vec3b>(0, 0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(entry[k] * 255, mapped[k], 1.5);
  EXPECT_GT(entry[0] + entry[1] + entry[2], 0.f);
  EXPECT_THROW(equalize_grid(m, 1, 1), std::invalid_argument);
  EXPECT_THROW(equalize_grid(m, 1, 257), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render::detail
