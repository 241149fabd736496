// The surface no photo sees takes the colours of the seen surface around it.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "render/unseen_fill.h"

namespace orthoface::render {
namespace {

constexpr int kW = 200, kH = 120;
const cv::Vec3b kHair(30, 40, 60), kSkin(120, 150, 200), kFill(128, 128, 128),
    kBackground(255, 0, 0);

// A head (x < 150) on a blue background: hair above row 60, skin below, and an unseen strip at
// x 120..139 drawn in the fill colour, as the synthesizer leaves it.
struct Scene {
  cv::Mat image, unseen, mask;
};
Scene strip_scene() {
  Scene s;
  s.image = cv::Mat(kH, kW, CV_8UC3, cv::Scalar(kBackground));
  s.mask = cv::Mat::zeros(kH, kW, CV_8U);
  s.unseen = cv::Mat::zeros(kH, kW, CV_8U);
  s.image(cv::Rect(0, 0, 150, 60)).setTo(cv::Scalar(kHair));
  s.image(cv::Rect(0, 60, 150, 60)).setTo(cv::Scalar(kSkin));
  s.mask(cv::Rect(0, 0, 150, kH)).setTo(255);
  s.image(cv::Rect(120, 0, 20, kH)).setTo(cv::Scalar(kFill));
  s.unseen(cv::Rect(120, 0, 20, kH)).setTo(255);
  return s;
}

double distance(cv::Vec3b a, cv::Vec3b b) {
  return std::sqrt(double((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                          (a[2] - b[2]) * (a[2] - b[2])));
}

TEST(UnseenFill, AStripTakesTheColoursBesideItNotTheBackgrounds) {
  Scene s = strip_scene();
  const cv::Mat before = s.image.clone();
  EXPECT_EQ(fill_unseen(s.image, s.unseen, s.mask, kFill), 20 * kH);
  // Well inside each half the strip is the hair's or the skin's colour; at the rows where the
  // two meet it lies between them. Never the fill's grey nor the background's blue.
  for (int x : {121, 130, 138}) {
    EXPECT_LT(distance(s.image.at<cv::Vec3b>(10, x), kHair), 8) << x;
    EXPECT_LT(distance(s.image.at<cv::Vec3b>(110, x), kSkin), 8) << x;
    const cv::Vec3b mid = s.image.at<cv::Vec3b>(60, x);
    EXPECT_LT(distance(mid, kHair), distance(kHair, kSkin)) << x;
    EXPECT_LT(distance(mid, kSkin), distance(kHair, kSkin)) << x;
    EXPECT_GT(distance(mid, kFill), 20) << x;
  }
  // Outside the strip nothing changed.
  const cv::Rect strip(120, 0, 20, kH);
  cv::Mat restored = s.image.clone();
  before(strip).copyTo(restored(strip));
  EXPECT_EQ(cv::norm(restored, before, cv::NORM_INF), 0);
}

TEST(UnseenFill, APartShareOfTheFillIsReplacedByItsShareOnly) {
  Scene s = strip_scene();
  // A pixel half seen (skin) and half fill, beside the strip.
  const cv::Point p(110, 100);
  s.unseen.at<uchar>(p) = 128;
  cv::Vec3b& px = s.image.at<cv::Vec3b>(p);
  for (int k = 0; k < 3; ++k) px[k] = cv::saturate_cast<uchar>(0.5 * kSkin[k] + 0.5 * kFill[k]);
  fill_unseen(s.image, s.unseen, s.mask, kFill);
  EXPECT_LT(distance(s.image.at<cv::Vec3b>(p), kSkin), 6);
}

TEST(UnseenFill, NothingToFillOrNothingSeenLeavesTheImage) {
  Scene s = strip_scene();
  const cv::Mat none = cv::Mat::zeros(kH, kW, CV_8U);
  const cv::Mat before = s.image.clone();
  EXPECT_EQ(fill_unseen(s.image, none, s.mask, kFill), 0);
  EXPECT_EQ(cv::norm(s.image, before, cv::NORM_INF), 0);
  // The whole surface unseen: no colour to take.
  cv::Mat all = s.mask.clone();
  EXPECT_EQ(fill_unseen(s.image, all, s.mask, kFill), 0);
  EXPECT_EQ(cv::norm(s.image, before, cv::NORM_INF), 0);
  // Unseen pixels off the surface (the background) are not the surface's holes.
  cv::Mat off = cv::Mat::zeros(kH, kW, CV_8U);
  off(cv::Rect(160, 0, 20, kH)).setTo(255);
  EXPECT_EQ(fill_unseen(s.image, off, s.mask, kFill), 0);
}

TEST(UnseenFill, BadInputsAreRefusedByName) {
  Scene s = strip_scene();
  cv::Mat empty;
  EXPECT_THROW(fill_unseen(empty, s.unseen, s.mask, kFill), std::invalid_argument);
  cv::Mat grey(kH, kW, CV_8U, cv::Scalar(0));
  EXPECT_THROW(fill_unseen(grey, s.unseen, s.mask, kFill), std::invalid_argument);
  try {
    fill_unseen(s.image, cv::Mat::zeros(kH, kW - 1, CV_8U), s.mask, kFill);
    FAIL() << "unseen shares of another size were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unseen shares"), std::string::npos) << e.what();
  }
  EXPECT_THROW(fill_unseen(s.image, s.unseen, cv::Mat(kH, kW, CV_32F, cv::Scalar(1)), kFill),
               std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
