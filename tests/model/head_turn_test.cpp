// The head's turn in the front photo, estimated from front points of a known turned head.
#include "model/head_turn.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "model/base_mesh.h"

namespace orthoface::model {
namespace {

constexpr double kYaw = 12 * M_PI / 180, kScale = 1.1;
const Eigen::Vector3d kAxis(5, 0, -20);

// The generic landmarks scaled, turned by kYaw about kAxis, seen by the ideal rig's front camera;
// the features with depth as stereo would give them.
struct TurnedHead {
  capture::RigCalibration rig = capture::ideal_rig(640, 480, 1.6);
  vision::FaceObservation observation;
  StereoData data;
  std::map<std::string, Eigen::Vector3d> truth;  // facing front
};

TurnedHead turned_head() {
  TurnedHead h;
  HeadTurn t;
  t.yaw_rad = kYaw;
  t.axis = kAxis;
  for (const auto& [name, g] : generic_landmarks()) {
    const Eigen::Vector3d facing = kAxis + kScale * g;
    const Eigen::Vector3d seen = turned(facing, t);
    h.truth[name] = facing;
    const Eigen::Vector2d px = capture::project(h.rig.front, seen);
    h.observation.front_trained[name] = {{px.x(), px.y()}, 0.9, "network-68", false};
    StereoPoint sp;
    sp.head_mm = seen;
    h.data.features[name] = sp;
  }
  h.data.silhouette = {{-70, 0}, {80, 0}};
  h.data.profile = {{110, 0}};
  return h;
}

TEST(HeadTurn, RecoversAKnownTurnAndTurnsTheDataBack) {
  const TurnedHead h = turned_head();
  const auto t = estimate_head_turn(h.observation, h.rig, h.data);
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->yaw_rad, kYaw, 1e-6);
  EXPECT_NEAR(t->scale, kScale, 1e-6);
  EXPECT_NEAR(t->axis.x(), kAxis.x(), 1e-6);
  EXPECT_NEAR(t->axis.z(), kAxis.z(), 1e-6);
  EXPECT_LT(t->residual_mm, 1e-6);
  const StereoData facing = facing_front(h.data, *t);
  for (const auto& [name, p] : facing.features)
    EXPECT_LT((p.head_mm - h.truth.at(name)).norm(), 1e-6) << name;
  EXPECT_NEAR(facing.centre_point.x(), kAxis.x(), 1e-6);
  EXPECT_NEAR(facing.silhouette[0].x(), -70, 1e-6);  // the width is kept
  EXPECT_NEAR(facing.profile[0].x(), kAxis.z() + 130 / std::cos(kYaw), 1e-6);
  // Turning back gives the observed points; a mesh turns the same way.
  const Eigen::Vector3d nose = turned(h.truth.at("nose_tip"), *t);
  mesh::TriMesh m;
  m.vertices = {h.truth.at("nose_tip")};
  turn_mesh(m, *t);
  EXPECT_LT((nose - h.data.features.at("nose_tip").head_mm).norm(), 1e-6);
  EXPECT_LT((m.vertices[0] - nose).norm(), 1e-12);
}

TEST(HeadTurn, AFrontalHeadHasNoTurnAndOneWrongPointIsDropped) {
  TurnedHead h = turned_head();
  HeadTurn none;
  none.axis = kAxis;
  for (const auto& [name, facing] : h.truth) {
    const Eigen::Vector2d px = capture::project(h.rig.front, facing);
    h.observation.front_trained[name].px = {px.x(), px.y()};
    h.data.features[name].head_mm = facing;
  }
  h.observation.front_trained["mouth_left"].px.x += 60;  // a landmarker's outlier
  const auto t = estimate_head_turn(h.observation, h.rig, h.data);
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->yaw_rad, 0, 1e-6);
  EXPECT_EQ(t->points, int(h.truth.size()) - 3);  // the outlier and both nose wings left out
}

TEST(HeadTurn, TooLittleToGoOnOrBadPoints) {
  TurnedHead h = turned_head();
  TurnedHead few = h;
  while (few.observation.front_trained.size() > 5)
    few.observation.front_trained.erase(few.observation.front_trained.begin());
  EXPECT_FALSE(estimate_head_turn(few.observation, few.rig, few.data));
  TurnedHead flat = h;  // no feature placed in depth
  for (auto& [name, p] : flat.data.features) p.has_depth = false;
  EXPECT_FALSE(estimate_head_turn(flat.observation, flat.rig, flat.data));
  h.observation.front_trained["nose_tip"].px.x = NAN;
  EXPECT_THROW(estimate_head_turn(h.observation, h.rig, h.data), std::invalid_argument);
  EXPECT_FALSE(estimate_head_turn(vision::FaceObservation{}, h.rig, h.data));
}

}  // namespace
}  // namespace orthoface::model
