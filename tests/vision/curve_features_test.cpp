// Extrema along a profile curve.
#include "vision/curve_features.h"

#include <cmath>

#include <gtest/gtest.h>

namespace ov = orthoface::vision;

TEST(CurveFeatures, AlternatingExtremaOfASine) {
  std::vector<double> v;
  for (int i = 0; i < 400; ++i) v.push_back(std::sin(i * 2 * M_PI / 100.0));
  const auto e = ov::alternating_extrema(v, 0.5);
  ASSERT_GE(e.size(), 6u);
  EXPECT_TRUE(e[0].is_max);
  EXPECT_NEAR(e[0].index, 25, 1);
  EXPECT_NEAR(e[1].index, 75, 1);
  EXPECT_TRUE(ov::alternating_extrema(std::vector<double>(50, 1.0), 0.1).empty());
}
