#include "model/stereo.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "synthetic_face.h"
#include "vision/landmarks.h"

namespace orthoface::model {
namespace {

TEST(Triangulate, IdealRigIsSeed004Eq1) {
  // Ideal rig 640x480, 2 px/mm: front column -> x, side column -> z, shared row -> y.
  const auto rig = capture::ideal_rig(640, 480, 2.0);
  const Eigen::Vector3d p(10, 20, 30);
  const Eigen::Vector2d f = capture::project(rig.front, p), s = capture::project(rig.side, p);
  EXPECT_NEAR(f.x(), 320 + 2 * 10, 1e-9);  // x right in the front image
  EXPECT_NEAR(f.y(), 240 - 2 * 20, 1e-9);  // y up = row up
  EXPECT_NEAR(s.x(), 320 - 2 * 30, 1e-9);  // the face (+z) toward the side image's left
  const Eigen::Vector3d q = triangulate(rig, f, s);
  EXPECT_NEAR((q - p).norm(), 0.0, 1e-9);
  // Rows that disagree by 4 px: y is their mean (1 mm off each view).
  const Eigen::Vector3d r = triangulate(rig, f, s + Eigen::Vector2d(0, 4));
  EXPECT_NEAR(r.y(), 19.0, 1e-9);
  EXPECT_NEAR(r.x(), 10.0, 1e-9);
  EXPECT_NEAR(r.z(), 30.0, 1e-9);
}

TEST(Triangulate, PerspectiveRigRecoversPoint) {
  capture::CameraModel intr;
  intr.projection = capture::Projection::Perspective;
  intr.fx = intr.fy = 1600;
  capture::RigCalibration rig;
  rig.front = capture::camera_at(intr, 0, 0, 1000);
  rig.side = capture::camera_at(intr, M_PI / 2, 0, 1000);
  const Eigen::Vector3d p(-25, 35, 80);
  const Eigen::Vector3d q =
      triangulate(rig, capture::project(rig.front, p), capture::project(rig.side, p));
  EXPECT_NEAR((q - p).norm(), 0.0, 1e-6);
}

TEST(Triangulate, ParallelRaysThrow) {
  auto rig = capture::ideal_rig(640, 480, 2.0);
  rig.side = rig.front;
  EXPECT_THROW(triangulate(rig, {1, 1}, {2, 2}), std::invalid_argument);
}

TEST(StereoMatch, SyntheticFaceGivesTrue3d) {
  const auto s = testing::synthetic_face({1.1, 0.95, 1.05}, {2, -3, 4});
  const StereoData d = stereo_match(s.observation, s.rig);
  for (const auto& [name, v] : s.truth.features) {
    ASSERT_TRUE(d.features.count(name)) << name;
    const StereoPoint& p = d.features.at(name);
    EXPECT_TRUE(p.has_depth) << name;
    // Right-side features take depth from their left twin: exact for a symmetric face.
    EXPECT_NEAR((p.head_mm - s.truth.mesh.vertices[v]).norm(), 0.0, 1e-6) << name;
    EXPECT_LT(p.mismatch_px, 1e-6) << name;
  }
  const int slice = 10;
  const Eigen::Vector3d c = s.truth.mesh.vertices[s.truth.centre(slice)];
  ASSERT_TRUE(profile_z_at(d, c.y()));
  EXPECT_NEAR(*profile_z_at(d, c.y()), c.z(), 1e-6);
  EXPECT_NEAR(centre_x_at(d, c.y()), 2.0, 1e-9);
  const Eigen::Vector3d l = s.truth.mesh.vertices[s.truth.slices[slice].back()];
  EXPECT_NEAR(*silhouette_x_at(d, l.y(), +1), l.x(), 1e-6);
  const Eigen::Vector3d r = s.truth.mesh.vertices[s.truth.slices[slice].front()];
  EXPECT_NEAR(*silhouette_x_at(d, r.y(), -1), r.x(), 1e-6);
  EXPECT_FALSE(silhouette_x_at(d, 500.0, +1));
}

TEST(StereoMatch, DisagreeingViewsAreReportedOrDropped) {
  auto s = testing::synthetic_face({1, 1, 1}, {0, 0, 0});
  s.observation.side.features["nose_tip"].px.y += 14;  // 14 px row mismatch: warned
  s.observation.side.features["chin"].px.y += 100;     // 100 px: dropped
  const StereoData d = stereo_match(s.observation, s.rig);
  ASSERT_TRUE(d.features.count("nose_tip"));
  EXPECT_NEAR(d.features.at("nose_tip").mismatch_px, 7.0, 1e-6);  // y split between views
  EXPECT_FALSE(d.features.count("chin"));
  EXPECT_EQ(d.warnings.size(), 1u + 1u);
}

TEST(StereoMatch, FrontOnlyFeatureHasNoDepth) {
  auto s = testing::synthetic_face({1, 1, 1}, {0, 0, 0});
  s.observation.side.features.erase("eye_left_outer");
  const StereoData d = stereo_match(s.observation, s.rig);
  EXPECT_FALSE(d.features.at("eye_left_outer").has_depth);
  EXPECT_FALSE(d.features.at("eye_right_outer").has_depth);
  EXPECT_TRUE(d.features.at("nose_tip").has_depth);
}

TEST(StereoMatch, SideCameraOnTheRightIsMirrored) {
  auto s = testing::synthetic_face({1, 1, 1}, {0, 0, 0});
  auto mirrored = s.observation;
  mirrored.side_faces_left = false;
  for (auto& p : mirrored.side.boundary) p.x = 640 - p.x;
  mirrored.side.features.clear();
  for (auto [name, f] : s.observation.side.features) {
    f.px.x = 640 - f.px.x;
    mirrored.side.features[vision::mirrored_name(name)] = f;
  }
  const StereoData a = stereo_match(s.observation, s.rig), b = stereo_match(mirrored, s.rig);
  for (const auto& [name, p] : a.features)
    EXPECT_NEAR((p.head_mm - b.features.at(name).head_mm).norm(), 0.0, 1e-9) << name;
}

TEST(StereoMatch, BadObservationsThrow) {
  const auto s = testing::synthetic_face({1, 1, 1}, {0, 0, 0});
  auto o = s.observation;
  o.front.boundary.resize(2);
  EXPECT_THROW(stereo_match(o, s.rig), std::invalid_argument);  // no silhouette
  o = s.observation;
  o.side.boundary.clear();
  EXPECT_THROW(stereo_match(o, s.rig), std::invalid_argument);  // no profile
  o = s.observation;
  o.front.features["nose_tip"].px.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(stereo_match(o, s.rig), std::invalid_argument);
  o = s.observation;
  o.side.boundary[3].y = std::numeric_limits<double>::infinity();
  EXPECT_THROW(stereo_match(o, s.rig), std::invalid_argument);
  o = s.observation;
  for (auto& p : o.side.boundary) p.y += 400;  // profile far below the silhouette
  EXPECT_THROW(stereo_match(o, s.rig), std::invalid_argument);
  StereoOptions bad;
  bad.reject_mismatch_px = 1;
  EXPECT_THROW(stereo_match(s.observation, s.rig, bad), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::model
