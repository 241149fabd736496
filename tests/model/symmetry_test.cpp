// The mid-sagittal plane from named landmarks, and the reflection through it.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "model/symmetry.h"

namespace orthoface::model {
namespace {

// Feature pairs mirrored about the plane x = 16 (a face 16 mm right of the head frame's origin).
std::map<std::string, Eigen::Vector3d> offset_face() {
  return {{"eye_left_outer", {16 + 45, 0, 25}}, {"eye_right_outer", {16 - 45, 0, 25}},
          {"mouth_left", {16 + 25, -85, 45}},   {"mouth_right", {16 - 25, -85, 45}},
          {"nose_tip", {16, -48, 75}},          {"chin", {16, -125, 50}},
          {"not_a_feature", {500, 0, 0}}};
}

TEST(Symmetry, PlaneOfAFaceOffCentreIsFound) {
  const auto plane = mid_sagittal_plane(offset_face());
  ASSERT_TRUE(plane.has_value());
  EXPECT_NEAR(plane->x(), 1.0, 1e-12);  // normal toward the subject's left (+x)
  EXPECT_NEAR(plane->y(), 0.0, 1e-12);
  EXPECT_NEAR(plane->z(), 0.0, 1e-12);
  EXPECT_NEAR(plane->w(), 16.0, 1e-9);
}

TEST(Symmetry, ReflectionMapsEachFeatureOntoItsTwin) {
  const auto lm = offset_face();
  const Eigen::Matrix4d m = reflection(*mid_sagittal_plane(lm));
  const Eigen::Vector3d left = lm.at("eye_left_outer"), right = lm.at("eye_right_outer");
  EXPECT_LT(((m * left.homogeneous()).head<3>() - right).norm(), 1e-9);
  EXPECT_LT(((m * lm.at("nose_tip").homogeneous()).head<3>() - lm.at("nose_tip")).norm(), 1e-9);
  EXPECT_LT((m * m - Eigen::Matrix4d::Identity()).norm(), 1e-12);  // an involution
}

TEST(Symmetry, TooFewPairsGiveNoPlane) {
  auto lm = offset_face();
  lm.erase("mouth_right");
  EXPECT_FALSE(mid_sagittal_plane(lm).has_value());
  EXPECT_FALSE(mid_sagittal_plane({}).has_value());
}

TEST(Symmetry, RejectsBadInputNamingIt) {
  auto lm = offset_face();
  lm["chin"].y() = NAN;
  try {
    mid_sagittal_plane(lm);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("chin"), std::string::npos);
  }
  EXPECT_THROW(reflection(Eigen::Vector4d(2, 0, 0, 0)), std::invalid_argument);
  EXPECT_THROW(reflection(Eigen::Vector4d(NAN, 0, 0, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::model
