// The photo-pair pipeline as a library: how the side photo is registered to the front.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "model/evaluate.h"
#include "model/stereo.h"
#include "reconstruct/identity.h"
#include "reconstruct/reconstruction.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/truth_observation.h"
#include "tests/common/test_data.h"
#include "vision/face_descriptor.h"
#include "vision/landmarks.h"

namespace orthoface::reconstruct {
namespace {

// A perfect observation of a sim head whose side photo was taken `shift` rows lower (its whole
// image moved down): profile and side features `shift` px down.
vision::FaceObservation shifted_side(double shift) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(2), sim::RigOptions{});
  vision::FaceObservation obs = sim::truth_observation(cap);
  for (auto& p : obs.side.boundary) p.y += shift;
  for (auto& [n, f] : obs.side.features) f.px.y += shift;
  return obs;
}

// Without a rig the side camera's rows come from the midline features found in both photos: a
// side photo taken lower is registered by its own features.
TEST(Pipeline, SidePhotoIsRegisteredByFeaturesFoundInEachPhoto) {
  const vision::FaceObservation obs = shifted_side(18);
  const Reconstruction r = from_observation(obs, {}, {});
  EXPECT_NEAR(r.rig.side.cy - r.rig.front.cy, 18.0, 0.5) << r.report.scale_note;
  EXPECT_NE(r.report.scale_note.find("found in each photo on its own"), std::string::npos);
}

// Front midline rows copied from the profile (the seed's filters) say nothing about the offset:
// the map they give is the identity whatever the photos' offset (the old, circular registration).
TEST(Pipeline, FrontRowsCopiedFromTheProfileCannotRegister) {
  vision::FaceObservation obs = shifted_side(18);
  for (auto& [n, f] : obs.front.features) {
    if (!vision::is_landmark_name(n) || vision::mirrored_name(n) != n) continue;
    const auto s = obs.side.features.find(n);
    if (s == obs.side.features.end()) continue;
    f.px.y = s->second.px.y;
    f.method = "centre-line+profile-row";
  }
  const Reconstruction r = from_observation(obs, {}, {});
  EXPECT_NEAR(r.rig.side.cy - r.rig.front.cy, 0.0, 0.5);
  EXPECT_NE(r.report.scale_note.find("came from the side photo"), std::string::npos);
}

// The input check runs before modelling: a swapped pair throws InputRefused naming the check;
// `force` models it with the failure first among the warnings; check_input = false skips it.
TEST(Pipeline, TheInputCheckRefusesOrRecordsAWrongPair) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(4), sim::RigOptions{});
  try {
    from_photos(cap.side, cap.front);
    ADD_FAILURE() << "a swapped pair was modelled";
  } catch (const InputRefused& e) {
    EXPECT_EQ(e.check(), "swapped");
    EXPECT_EQ(std::string(e.what()).rfind("input check swapped: ", 0), 0u) << e.what();
  }
  ReconstructOptions o;
  o.force = true;
  const Reconstruction forced = from_photos(cap.side, cap.front, o);
  ASSERT_FALSE(forced.report.warnings.empty());
  EXPECT_EQ(forced.report.warnings[0].rfind("input check swapped failed", 0), 0u);
  EXPECT_EQ(forced.report.input_checks.size(), 11u);
  o.force = false;
  o.check_input = false;
  EXPECT_TRUE(from_photos(cap.side, cap.front, o).report.input_checks.empty());
  const Reconstruction right = from_photos(cap.front, cap.side);
  ASSERT_EQ(right.report.input_checks.size(), 11u);
  for (const auto& c : right.report.input_checks)
    EXPECT_TRUE(c.passed) << c.name << ": " << c.problem;
}

// The identity check (asked for) runs after modelling: a right sim pair passes with a measured
// distance; with a limit below it the pair is refused by name before anything is returned, and
// `force` records it. (Sim heads all look alike to the network, so another subject's side is
// not a test of refusal: docs/input_check.md.)
TEST(Pipeline, TheIdentityCheckMeasuresAndRefusesByName) {
  if (!vision::shared_describer())
    GTEST_SKIP() << "no face-recognition weights (scripts/fetch-face-model.sh)";
  const sim::Capture cap = sim::simulate_capture(sim::make_head(4), sim::RigOptions{});
  ReconstructOptions o;
  o.check_identity = true;
  const Reconstruction right = from_photos(cap.front, cap.side, o);
  ASSERT_EQ(right.report.input_checks.size(), 12u);
  const vision::InputCheck& c = right.report.input_checks.back();
  EXPECT_EQ(c.name, "same_person_face");
  EXPECT_TRUE(c.passed) << c.problem;
  EXPECT_GT(c.value, 0.0);
  EXPECT_LT(c.value, 0.5);  // sim heads 0-5: 0.28-0.42 (face-api.js's own crops)
  o.input_limits.max_face_distance = c.value / 2;
  try {
    from_photos(cap.front, cap.side, o);
    ADD_FAILURE() << "a pair beyond the face distance limit was modelled";
  } catch (const InputRefused& e) {
    EXPECT_EQ(e.check(), "same_person_face");
  }
  o.force = true;
  const Reconstruction forced = from_photos(cap.front, cap.side, o);
  ASSERT_FALSE(forced.report.warnings.empty());
  EXPECT_EQ(forced.report.warnings[0].rfind("input check same_person_face failed", 0), 0u);
  o.input_limits.max_face_distance = 0;
  EXPECT_THROW(from_photos(cap.front, cap.side, o), std::invalid_argument);  // a bad limit
}

// Real photos (FRMDB, read from ../shared/data): 010's front with its own side passes, with
// 013's side it is refused. Before the check looked at three views aligned by the raw flow the
// wrong pairing passed (0.651 against the limit 0.68 then; now 0.80, the right pair 0.57).
TEST(Pipeline, TheIdentityCheckRefusesAnotherPersonsSide) {
  if (!vision::shared_describer())
    GTEST_SKIP() << "no face-recognition weights (scripts/fetch-face-model.sh)";
  const std::string dir = testing::shared_data("frmdb_multiview");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/frmdb_multiview";
  const cv::Mat front = cv::imread(dir + "/010/Img_33.JPG");
  const cv::Mat own_side = cv::imread(dir + "/010/Img_53.JPG");
  const cv::Mat other_side = cv::imread(dir + "/013/Img_53.JPG");
  ASSERT_FALSE(front.empty() || own_side.empty() || other_side.empty());
  ReconstructOptions o;
  o.observe.side_camera = vision::SideCamera::Right;
  o.check_identity = true;
  o.force = true;  // the identity check's own verdict, whatever the gate says
  auto verdict = [&](const cv::Mat& side) {
    const Reconstruction r = from_photos(front, side, o);
    return r.report.input_checks.back();
  };
  const vision::InputCheck right = verdict(own_side), wrong = verdict(other_side);
  ASSERT_EQ(right.name, "same_person_face");
  EXPECT_TRUE(right.passed) << right.value;
  EXPECT_FALSE(wrong.passed) << wrong.value;
}

// No value without something to compare: an empty reconstruction, or one without landmarks
// (the faces are placed where the model's landmarks project).
TEST(Pipeline, TheIdentityDistanceNeedsPhotosAndLandmarks) {
  EXPECT_FALSE(front_to_view_face_distance(Reconstruction{}));
  if (!vision::shared_describer())
    GTEST_SKIP() << "no face-recognition weights (scripts/fetch-face-model.sh)";
  const sim::Capture cap = sim::simulate_capture(sim::make_head(4), sim::RigOptions{});
  ReconstructOptions o;
  o.check_input = false;
  Reconstruction r = from_photos(cap.front, cap.side, o);
  EXPECT_TRUE(front_to_view_face_distance(r));
  r.landmarks.clear();
  EXPECT_FALSE(front_to_view_face_distance(r));
}

// The identity check views the face as adapted before smoothing (the smoothing hides two
// people's misfit): with the smoothing forced on a sim pair, the check's distance is that of the
// model made without smoothing, not that of the smoothed model it returns.
TEST(Pipeline, TheIdentityCheckViewsTheUnsmoothedFace) {
  if (!vision::shared_describer())
    GTEST_SKIP() << "no face-recognition weights (scripts/fetch-face-model.sh)";
  const sim::Capture cap = sim::simulate_capture(sim::make_head(4), sim::RigOptions{});
  ReconstructOptions smoothed;
  smoothed.adapt.rough_from_mm = 0;
  smoothed.adapt.rough_full_mm = 1e-3;
  ReconstructOptions raw;  // the face as adapted: not smoothed, fins and overreach left
  raw.adapt.smooth_iterations = 0;
  raw.adapt.open_fins = raw.adapt.inside_silhouette = false;
  const Reconstruction s = from_photos(cap.front, cap.side, smoothed);
  ASSERT_EQ(s.report.surface_smoothed_share, 1.0);
  const auto d_smoothed = front_to_view_face_distance(s);
  const auto d_raw = front_to_view_face_distance(from_photos(cap.front, cap.side, raw));
  ASSERT_TRUE(d_smoothed && d_raw);
  ASSERT_GT(std::abs(*d_smoothed - *d_raw), 1e-6);  // else the test could not tell them apart
  smoothed.check_identity = true;
  const Reconstruction checked = from_photos(cap.front, cap.side, smoothed);
  EXPECT_NEAR(checked.report.input_checks.back().value, *d_raw, 1e-9);
  EXPECT_EQ(checked.mesh.vertices, s.mesh.vertices);  // the model itself stays smoothed
}

// Without a rig a side photo of another resolution is rescaled to the front photo's height (it
// was refused beyond 1.5x): the model matches the one from equal photos and the report says so.
TEST(Pipeline, ASidePhotoOfAnotherSizeIsRescaled) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(2), sim::RigOptions{});
  cv::Mat big_side;
  cv::resize(cap.side, big_side, cv::Size(), 2.0, 2.0, cv::INTER_LINEAR);
  const Reconstruction same = from_photos(cap.front, cap.side);
  const Reconstruction scaled = from_photos(cap.front, big_side);
  EXPECT_DOUBLE_EQ(same.report.side_photo_scale, 1.0);
  EXPECT_DOUBLE_EQ(scaled.report.side_photo_scale, 0.5);
  EXPECT_EQ(scaled.side.size(), cap.side.size());
  // Resampling moves the profile's points by a fraction of a pixel; the pogonion (the chin's
  // most forward point on a flat curve) moves most (6 mm measured, the others 2.4 mm or less).
  std::vector<double> moved;
  for (const auto& [name, p] : same.landmarks) {
    const auto it = scaled.landmarks.find(name);
    ASSERT_NE(it, scaled.landmarks.end()) << name;
    moved.push_back((it->second - p).norm());
  }
  std::sort(moved.begin(), moved.end());
  EXPECT_LT(moved[moved.size() / 2], 1.0);  // mm
  EXPECT_LT(moved.back(), 8.0);
  // With a rig the photos must be the rig's size: nothing is rescaled.
  ReconstructOptions o;
  o.rig = cap.nominal_rig;
  EXPECT_THROW(from_photos(cap.front, big_side, o), std::invalid_argument);
}

// A head turned in the rig (both true cameras swung about it) is modelled facing front and
// turned back when it turned away from the side camera; turned toward it, it is taken as frontal
// unless asked (real pairs lose then: docs/views_accuracy.md). The sim's side camera stands at
// +x, and the cameras swung by +12 degrees show the face turned toward it.
TEST(Pipeline, AHeadTurnedAwayFromTheSideCameraIsModelledFacingFront) {
  for (const double yaw : {12.0, -12.0}) {
    sim::RigOptions ro;
    ro.front_error.yaw_deg = ro.side_error.yaw_deg = yaw;
    const sim::Capture cap = sim::simulate_capture(sim::make_head(2), ro);
    ReconstructOptions o;
    o.rig = cap.nominal_rig;
    const Reconstruction r = from_photos(cap.front, cap.side, o);
    // Within the estimate's error on sim heads (generic depths: 16.4 degrees read for 12).
    EXPECT_NEAR(std::abs(r.report.head_yaw_deg), 12, 6) << "cameras turned " << yaw;
    ASSERT_EQ(capture::photographed_side_sign(r.photo_rig), 1.0);
    EXPECT_GT(r.report.head_yaw_deg * yaw, 0) << "cameras turned " << yaw;
    EXPECT_EQ(r.report.head_turn_corrected, yaw < 0) << "cameras turned " << yaw;
    o.turn_toward_side = true;
    EXPECT_TRUE(from_photos(cap.front, cap.side, o).report.head_turn_corrected);
    o.min_head_turn_deg = -1;
    EXPECT_FALSE(from_photos(cap.front, cap.side, o).report.head_turn_corrected);
  }
}

// On sim heads turned 20 degrees either way in the rig, the model built facing front and turned
// back is closer to the truth than the one built as if the head faced the camera.
TEST(Pipeline, ATurnedSimHeadTurnedBackIsCloserToTheTruth) {
  const sim::Head head = sim::make_head(3);
  const model::FaceRegion region = model::face_region(head.landmarks);
  for (const double yaw : {20.0, -20.0}) {
    sim::RigOptions ro;
    ro.front_error.yaw_deg = ro.side_error.yaw_deg = yaw;
    const sim::Capture cap = sim::simulate_capture(head, ro);
    // The truth as the believed (nominal) cameras see it: the true cameras' turn undone.
    const Eigen::Isometry3d to_head =
        cap.true_rig.front.cam_from_head.inverse() * cap.nominal_rig.front.cam_from_head;
    double error[2];
    for (const bool turn_back : {false, true}) {
      ReconstructOptions o;
      o.rig = cap.nominal_rig;
      o.min_head_turn_deg = turn_back ? 5 : -1;
      o.turn_toward_side = true;
      const Reconstruction r = from_photos(cap.front, cap.side, o);
      ASSERT_EQ(r.report.head_turn_corrected, turn_back);
      mesh::TriMesh m = r.mesh;
      for (Eigen::Vector3d& v : m.vertices) v = to_head * v;
      error[turn_back] = model::reconstruction_error(m, head.mesh, region).relative;
    }
    EXPECT_LT(error[1], 0.9 * error[0]) << "cameras turned " << yaw;
  }
}

// A head modelled facing front is held inside the front silhouette once turned back to where it
// stood, against the silhouette as measured: clamped in the facing-front frame instead, the
// turned face's side was cut (FRMDB 001's correct pair then failed the identity check, 0.805
// against its limit of 0.71).
TEST(Pipeline, ATurnedBackHeadStaysInsideTheSilhouetteAsItStood) {
  const sim::Head head = sim::make_head(3);
  sim::RigOptions ro;
  ro.front_error.yaw_deg = ro.side_error.yaw_deg = 20;
  const sim::Capture cap = sim::simulate_capture(head, ro);
  ReconstructOptions o;
  o.rig = cap.nominal_rig;
  o.min_head_turn_deg = 5;
  o.turn_toward_side = true;
  const Reconstruction r = from_photos(cap.front, cap.side, o);
  ASSERT_TRUE(r.report.head_turn_corrected);
  EXPECT_GT(r.report.clamped_to_silhouette, 0);  // report.json says what the clamp did
  const model::StereoData d = model::stereo_match(r.observation, r.rig);
  int beyond = 0, inside_rows = 0;
  for (const Eigen::Vector3d& v : r.mesh.vertices) {
    const auto right = model::silhouette_x_at(d, v.y(), -1),
               left = model::silhouette_x_at(d, v.y(), 1);
    if (!right || !left) continue;
    ++inside_rows;
    const double margin = o.adapt.silhouette_margin_mm + 1e-6;
    beyond += v.x() < *right - margin || v.x() > *left + margin;
  }
  EXPECT_GT(inside_rows, 1000);
  EXPECT_EQ(beyond, 0);
}

TEST(Pipeline, BadInputLimitsAreRefused) {
  ReconstructOptions o;
  o.input_limits.max_front_turn = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::reconstruct
