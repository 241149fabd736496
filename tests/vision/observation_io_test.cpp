// observation.json written and read back.
#include "vision/observation_io.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/common/test_data.h"

namespace ov = orthoface::vision;

TEST(ObservationIo, RoundTripAndMalformed) {
  ov::FaceObservation o;
  o.front.width = 640;
  o.front.boundary = {{1.5, 2.5}, {3, 4}};
  o.front.features["nose_tip"] = {{320.5, 240.5}, 0.8, "profile-row", false};
  o.side.features["chin"] = {{100, 300}, 0.3, "mirrored", true};
  o.roll_rad = 0.01;
  o.side_faces_left = false;
  o.warnings = {"w1"};
  o.front_trained["nose_tip"] = {{322.25, 241}, 0.9, "network-68", false};
  const auto dir = orthoface::testing::temp_dir("observation_io");
  ov::write_observation(o, (dir / "observation.json").string());
  const ov::FaceObservation r = ov::read_observation((dir / "observation.json").string());
  EXPECT_EQ(r.front.boundary.size(), 2u);
  EXPECT_DOUBLE_EQ(r.front.features.at("nose_tip").px.x, 320.5);
  EXPECT_TRUE(r.side.features.at("chin").mirrored);
  EXPECT_FALSE(r.side_faces_left);
  EXPECT_EQ(r.warnings, o.warnings);
  EXPECT_DOUBLE_EQ(r.front_trained.at("nose_tip").px.x, 322.25);
  auto j = ov::to_json(o);
  j.erase("front_trained");  // written before the field existed: still read
  EXPECT_TRUE(ov::observation_from_json(j).front_trained.empty());
  j["front_trained"] = {{"nose_tip", {{"x", "left"}}}};
  EXPECT_THROW(ov::observation_from_json(j), std::invalid_argument);
  j = ov::to_json(o);
  j["front"]["features"]["not_a_landmark"] = j["front"]["features"]["nose_tip"];
  EXPECT_THROW(ov::observation_from_json(j), std::invalid_argument);
  j = ov::to_json(o);
  j["centre_line"].erase("roll_rad");
  EXPECT_THROW(ov::observation_from_json(j), std::invalid_argument);
  EXPECT_THROW(ov::read_observation((dir / "missing.json").string()), std::runtime_error);
  const std::string bad = orthoface::testing::shared_data("bad_inputs/json_malformed.json");
  if (!bad.empty()) {
    EXPECT_THROW(ov::read_observation(bad), std::runtime_error);
  }
}
