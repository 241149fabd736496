// The front photo's centre line.
#include "vision/front_features.h"

#include <gtest/gtest.h>

namespace ov = orthoface::vision;

TEST(CentreLine, MirrorPointAcrossTiltedAxis) {
  ov::CentreLine c{100, 50, 0.0, 1};
  const cv::Point2d m = ov::mirror_point(c, {90, 10});
  EXPECT_NEAR(m.x, 110, 1e-9);
  EXPECT_NEAR(m.y, 10, 1e-9);
  c.roll_rad = 0.2;
  const cv::Point2d back = ov::mirror_point(c, ov::mirror_point(c, {37, 81}));
  EXPECT_NEAR(back.x, 37, 1e-9);
  EXPECT_NEAR(back.y, 81, 1e-9);
}
