#include "judge/head_region.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace orthoface::judge {
namespace {

// A head on a cluttered background: a skin-coloured face, dark hair above and beside it, a
// neck, all over random grey blocks; `head` is the truth (face and hair, not the neck).
cv::Mat head_photo(cv::Mat& head) {
  cv::Mat photo(480, 640, CV_8UC3);
  cv::RNG rng(7);
  for (int y = 0; y < photo.rows; y += 16)
    for (int x = 0; x < photo.cols; x += 16) {
      const int g = rng.uniform(60, 200);
      photo(cv::Rect(x, y, 16, 16)).setTo(cv::Scalar(g, g + 10, g - 20));
    }
  head = cv::Mat::zeros(photo.size(), CV_8U);
  cv::ellipse(head, {320, 200}, {105, 125}, 0, 0, 360, 255, cv::FILLED);  // hair and skull
  photo.setTo(cv::Scalar(20, 30, 45), head);
  cv::Mat face = cv::Mat::zeros(photo.size(), CV_8U);
  cv::ellipse(face, {320, 240}, {75, 95}, 0, 0, 360, 255, cv::FILLED);
  photo.setTo(cv::Scalar(120, 150, 200), face);
  head |= face;
  cv::rectangle(photo, {290, 330}, {350, 480}, cv::Scalar(115, 145, 195), cv::FILLED);  // neck
  return photo;
}

TEST(HeadRegion, CutsTheHeadWithItsHairOutOfClutter) {
  cv::Mat truth;
  const cv::Mat photo = head_photo(truth);
  const cv::Mat region = head_region(photo, cv::Rect(260, 170, 120, 130));
  ASSERT_EQ(region.size(), photo.size());
  ASSERT_EQ(region.type(), CV_8UC1);
  // Above the chin (row 330) the region is the head, hair included.
  const cv::Mat eye = cv::Mat::eye(2, 3, CV_64F);
  EXPECT_GT(head_iou(region, eye, truth, 330), 0.9);
  // The face box's middle is head, a corner of the frame is not.
  EXPECT_GT(region.at<uchar>(240, 320), 0);
  EXPECT_EQ(region.at<uchar>(10, 10), 0);
  // The same region whatever the thread's random state, which it leaves as it was.
  cv::RNG& rng = cv::theRNG();
  for (int i = 0; i < 1000; ++i) rng.next();
  const uint64 before = rng.state;
  EXPECT_EQ(cv::countNonZero(head_region(photo, cv::Rect(260, 170, 120, 130)) != region), 0);
  EXPECT_EQ(rng.state, before);
}

// A head turned to the image's left on a dark cloth, as in a 45-degree portrait: dark-brown hair
// wide behind the face, the face at the box's left so that the box's lower right is cloth, and
// dlib's 68 points of such a face (nose tip out beyond the near eye).
cv::Mat turned_head_photo(cv::Mat& head, Landmarks68& points) {
  cv::Mat photo(480, 640, CV_8UC3, cv::Scalar(55, 30, 35));  // dark blue-purple cloth
  cv::Mat noise(photo.size(), CV_8UC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 6);
  head = cv::Mat::zeros(photo.size(), CV_8U);
  cv::ellipse(head, {360, 170}, {110, 110}, 0, 0, 360, 255, cv::FILLED);  // hair and skull
  cv::Mat face = cv::Mat::zeros(photo.size(), CV_8U);
  cv::ellipse(face, {285, 245}, {55, 90}, 0, 0, 360, 255, cv::FILLED);
  photo.setTo(cv::Scalar(30, 40, 60), head);  // dark brown
  photo.setTo(cv::Scalar(120, 150, 200), face);
  head |= face;
  photo += noise;
  for (int i = 0; i < 17; ++i) {  // the jaw, round the face's lower half
    const double a = CV_PI * i / 16.0;
    points[size_t(i)] = {285 - 50 * std::cos(a), 245 + 80 * std::sin(a)};
  }
  for (int i = 17; i < 27; ++i) points[size_t(i)] = {245 + 7.0 * (i - 17), 205};  // brows
  for (int i = 27; i < 36; ++i) points[size_t(i)] = {250 - 1.0 * (i - 27), 220 + 5.0 * (i - 27)};
  for (int i = 36; i < 48; ++i) points[size_t(i)] = {255 + 5.0 * (i - 36), 225};  // eyes
  points[30] = {238, 262};                                                        // nose tip
  for (int i = 48; i < 68; ++i) points[size_t(i)] = {255 + 2.0 * (i - 48), 290};  // mouth
  return photo;
}

TEST(HeadRegion, TheFacePointsKeepTheBackgroundBesideATurnedFaceOut) {
  cv::Mat truth;
  Landmarks68 points;
  const cv::Mat photo = turned_head_photo(truth, points);
  const cv::Rect box(240, 170, 150, 150);
  const cv::Mat region = head_region(photo, box, &points);
  const cv::Mat eye = cv::Mat::eye(2, 3, CV_64F);
  EXPECT_GT(head_iou(region, eye, truth, 335), 0.9);
  EXPECT_EQ(region.at<uchar>(285, 355), 0);  // in the box's middle, but cloth
  EXPECT_GT(region.at<uchar>(120, 420), 0);  // the hair behind the face
  // The box alone takes its middle for face, cloth and all.
  EXPECT_GT(head_region(photo, box).at<uchar>(285, 355), 0);
}

TEST(HeadRegion, RefusesBadPhotosAndBoxes) {
  cv::Mat truth;
  const cv::Mat photo = head_photo(truth);
  EXPECT_THROW(head_region(cv::Mat(), {10, 10, 50, 50}), std::invalid_argument);
  cv::Mat grey;
  cv::cvtColor(photo, grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(head_region(grey, {260, 170, 120, 130}), std::invalid_argument);
  EXPECT_THROW(head_region(photo, {600, 400, 120, 130}), std::invalid_argument);  // outside
  EXPECT_THROW(head_region(photo, {260, 170, 2, 2}), std::invalid_argument);      // too small
  Landmarks68 not_finite;
  not_finite.fill({300, 200});
  not_finite[40].y = NAN;
  EXPECT_THROW(head_region(photo, {260, 170, 120, 130}, &not_finite), std::invalid_argument);
  Landmarks68 far_off = not_finite;
  far_off[40] = {300, 1e12};  // finite, but no face of this photo (and past int's range)
  EXPECT_THROW(head_region(photo, {260, 170, 120, 130}, &far_off), std::invalid_argument);
  far_off[40] = {-20, 210};  // a face cut by the frame's edge is fine
  EXPECT_EQ(head_region(photo, {260, 170, 120, 130}, &far_off).size(), photo.size());
}

TEST(HeadIou, OverlapAfterTheTransformAboveTheCut) {
  cv::Mat a = cv::Mat::zeros(100, 100, CV_8U), b = a.clone();
  a(cv::Rect(10, 10, 40, 40)).setTo(255);
  b(cv::Rect(30, 10, 40, 40)).setTo(255);
  const cv::Mat eye = cv::Mat::eye(2, 3, CV_64F);
  EXPECT_DOUBLE_EQ(head_iou(a, eye, a, 100), 1.0);
  // 20 of 40 columns shared: 800 / (1600 + 1600 - 800).
  EXPECT_NEAR(head_iou(a, eye, b, 100), 800.0 / 2400.0, 1e-9);
  // Moved 20 px right, a is b.
  cv::Mat shift = eye.clone();
  shift.at<double>(0, 2) = 20;
  EXPECT_DOUBLE_EQ(head_iou(a, shift, b, 100), 1.0);
  // Only the rows above the cut count: cut at row 30, 20 rows of each square.
  EXPECT_NEAR(head_iou(a, eye, b, 30), 400.0 / 1200.0, 1e-9);
  EXPECT_EQ(head_iou(a, eye, b, 5), 0.0);  // both empty above row 5
}

TEST(HeadIou, RefusesBadMasksAndTransforms) {
  const cv::Mat m = cv::Mat::zeros(20, 20, CV_8U), eye = cv::Mat::eye(2, 3, CV_64F);
  EXPECT_THROW(head_iou(cv::Mat(), eye, m, 10), std::invalid_argument);
  EXPECT_THROW(head_iou(m, eye, cv::Mat::zeros(20, 20, CV_32F), 10), std::invalid_argument);
  EXPECT_THROW(head_iou(m, cv::Mat::eye(3, 3, CV_64F), m, 10), std::invalid_argument);
}

TEST(BlackFraction, CountsPixelsBlackInEveryChannel) {
  cv::Mat image(10, 10, CV_8UC3, cv::Scalar(0, 0, 0));
  image(cv::Rect(0, 0, 10, 5)).setTo(cv::Scalar(0, 0, 1));  // dark red is not black
  EXPECT_DOUBLE_EQ(black_fraction(image), 0.5);
  EXPECT_DOUBLE_EQ(black_fraction(cv::Mat(4, 4, CV_8U, cv::Scalar(9))), 0.0);
  EXPECT_THROW(black_fraction(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(black_fraction(cv::Mat(4, 4, CV_32FC3)), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::judge
