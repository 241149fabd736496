#pragma once
// Test expectations shared by the capture tests: two cameras or poses equal.

#include <gtest/gtest.h>

#include "capture/camera_model.h"

namespace orthoface::testing {

// Rotation within `tolerance`, translation within `tolerance` relative to its length.
inline void expect_same_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                             double tolerance = 1e-12) {
  EXPECT_LT((a.linear() - b.linear()).norm(), tolerance);
  EXPECT_LT((a.translation() - b.translation()).norm(), tolerance * (1 + b.translation().norm()));
}

// The same projection, size, intrinsics (to the last few bits), distortion and pose.
inline void expect_same_camera(const capture::CameraModel& a, const capture::CameraModel& b,
                               double pose_tolerance = 1e-12) {
  EXPECT_EQ(a.projection, b.projection);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_DOUBLE_EQ(a.fx, b.fx);
  EXPECT_DOUBLE_EQ(a.fy, b.fy);
  EXPECT_DOUBLE_EQ(a.cx, b.cx);
  EXPECT_DOUBLE_EQ(a.cy, b.cy);
  EXPECT_EQ(a.distortion, b.distortion);
  expect_same_pose(a.cam_from_head, b.cam_from_head, pose_tolerance);
}

}  // namespace orthoface::testing
