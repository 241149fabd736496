#include "vision/profile_mask.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace orthoface::vision {
namespace {

TEST(ProfileMask, KeepsThePixelsBehindTheProfile) {
  ViewObservation side;
  side.width = 40;
  side.height = 30;
  side.boundary = {{20, 10}, {10, 15}, {20, 20}};  // a nose pointing left at row 15
  const cv::Mat left = profile_mask(side, true);
  EXPECT_EQ(left.at<uchar>(5, 0), 255);    // above the profile: not known, kept
  EXPECT_EQ(left.at<uchar>(15, 9), 0);     // in front of the nose tip
  EXPECT_EQ(left.at<uchar>(15, 11), 255);  // behind it
  EXPECT_EQ(left.at<uchar>(11, 16), 0);    // in front of the upper slope (x = 17 at y = 11.5)
  EXPECT_EQ(left.at<uchar>(11, 17), 255);
  const cv::Mat right = profile_mask(side, false);
  EXPECT_EQ(right.at<uchar>(15, 9), 255);
  EXPECT_EQ(right.at<uchar>(15, 11), 0);
  EXPECT_EQ(right.at<uchar>(25, 39), 255);  // below the profile
}

TEST(ProfileMask, AProfileOutsideTheRowsKeepsTheWholeImage) {
  ViewObservation side;
  side.width = 40;
  side.height = 30;
  side.boundary = {{20, -20}, {10, -5}};  // above the image
  EXPECT_EQ(cv::countNonZero(profile_mask(side, true)), 40 * 30);
}

TEST(ProfileMask, RefusesAViewWithoutSizeOrProfile) {
  ViewObservation side;
  side.width = 40;
  side.height = 30;
  side.boundary = {{20, 10}, {10, 15}, {20, 20}};
  ViewObservation empty = side;
  empty.boundary.resize(1);
  EXPECT_THROW(profile_mask(empty, true), std::invalid_argument);
  empty = side;
  empty.width = 0;
  EXPECT_THROW(profile_mask(empty, true), std::invalid_argument);
}

// The mask of an observation's own side photo; none for a photo of another size or without a
// profile (then the whole photo may texture).
TEST(ProfileMask, SidePhotoMaskOnlyForTheObservedPhoto) {
  FaceObservation obs;
  obs.side.width = 40;
  obs.side.height = 30;
  obs.side.boundary = {{20, 10}, {10, 15}, {20, 20}};
  obs.side_faces_left = true;
  const cv::Mat m = side_photo_mask(obs, {40, 30});
  ASSERT_EQ(m.size(), cv::Size(40, 30));
  EXPECT_EQ(cv::countNonZero(m != profile_mask(obs.side, true)), 0);
  EXPECT_TRUE(side_photo_mask(obs, {80, 60}).empty());  // another photo
  obs.side.boundary.resize(1);
  EXPECT_TRUE(side_photo_mask(obs, {40, 30}).empty());  // no profile
  obs.side = {};
  EXPECT_TRUE(side_photo_mask(obs, {0, 0}).empty());  // no view at all: no throw
}

}  // namespace
}  // namespace orthoface::vision
