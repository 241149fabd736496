#include "capture/calibration.h"

#include <cstdio>

#include <gtest/gtest.h>

#include "tests/capture/board_render.h"
#include "tests/common/test_data.h"

namespace orthoface::capture {
namespace {

using testing::render_board_views;
using testing::session_poses;

sim::RigOptions perspective_rig() {
  sim::RigOptions o;
  o.kind = sim::RigKind::Perspective;
  o.focal_px = 1000;  // 640x480 sees a 20 mm-square board whole when tilted
  return o;
}

Eigen::Isometry3d true_side_from_front(const RigCalibration& rig) {
  return rig.side.cam_from_head * rig.front.cam_from_head.inverse();
}

Checkerboard board() {
  Checkerboard b;
  b.cols = 9;
  b.rows = 6;
  b.square_mm = 25;
  return b;
}

TEST(CalibrateRig, RecoversSimulatedRigPose) {
  const RigCalibration truth = sim::true_rig(perspective_rig());
  auto views = render_board_views(board(), truth, session_poses(board(), 5));
  testing::hide_cross_views(views);
  CalibrationOptions o;
  o.board = board();
  const RigCalibrationReport rep = calibrate_rig(views.front, views.side, o);
  const Eigen::Isometry3d t = true_side_from_front(truth);
  const double rot_deg = rotation_error_deg(rep.side_from_front, t);
  const double trans_mm = (rep.side_from_front.translation() - t.translation()).norm();
  std::printf(
      "calibration (sim rig, %d/%d/%d views): rms front %.3f side %.3f stereo %.3f px, "
      "rotation error %.4f deg, translation error %.3f mm (of %.1f), fx %.2f/%.2f (true %.0f), "
      "predicted sd %.2f %.2f %.2f mm\n",
      rep.views_front, rep.views_side, rep.views_shared, rep.rms_front_px, rep.rms_side_px,
      rep.rms_stereo_px, rot_deg, trans_mm, t.translation().norm(), rep.rig.front.fx,
      rep.rig.side.fx, truth.front.fx, rep.translation_sd_mm.x(), rep.translation_sd_mm.y(),
      rep.translation_sd_mm.z());
  EXPECT_EQ(rep.views_shared, 5);
  EXPECT_LT(rep.rms_stereo_px, 0.5);
  // 13 views per camera at 640x480 give the focal length to ~1%, which bounds the baseline's
  // length (depth-scale) to about the same: measured 0.37 deg / 14 mm of 1414 mm.
  EXPECT_LT(rot_deg, 0.6);
  EXPECT_LT(trans_mm, 0.02 * t.translation().norm());
  EXPECT_NEAR(rep.rig.front.fx, truth.front.fx, 0.02 * truth.front.fx);
  EXPECT_NEAR(rep.rig.side.cx, truth.side.cx, 10.0);
  // The head frame: the two viewing directions are -z and -x, 90 deg apart.
  EXPECT_NEAR(view_direction(rep.rig.front).z(), -1.0, 1e-9);
  EXPECT_NEAR(view_direction(rep.rig.side).x(), -1.0, 0.01);
  // Written as the YAML `reconstruct --rig` reads.
  const auto dir = orthoface::testing::temp_dir("calibrate_rig");
  write_rig(rep.rig, (dir / "rig.yaml").string());
  const RigCalibration back = read_rig((dir / "rig.yaml").string());
  EXPECT_NEAR(back.side.fx, rep.rig.side.fx, 1e-6);
  EXPECT_LT(rotation_error_deg(back.side.cam_from_head, rep.rig.side.cam_from_head), 1e-6);
}

TEST(CalibrateRig, TooFewViewsSaysSo) {
  const RigCalibration truth = sim::true_rig(perspective_rig());
  auto poses = session_poses(board(), 2);
  poses.erase(poses.begin() + 2, poses.begin() + 16);  // 2 front, 0 side-only, 2 shared
  const auto views = render_board_views(board(), truth, poses);
  CalibrationOptions o;
  o.board = board();
  try {
    calibrate_rig(views.front, views.side, o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("need at least 4"), std::string::npos) << e.what();
  }
}

TEST(CalibrateRig, NoSharedViewIsAnError) {
  const RigCalibration truth = sim::true_rig(perspective_rig());
  auto views = render_board_views(board(), truth, session_poses(board(), 0));
  testing::hide_cross_views(views);
  CalibrationOptions o;
  o.board = board();
  try {
    calibrate_rig(views.front, views.side, o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("seen by both cameras"), std::string::npos) << e.what();
  }
}

TEST(CalibrateRig, OneSharedViewLeavesTranslationLoose) {
  const RigCalibration truth = sim::true_rig(perspective_rig());
  auto views = render_board_views(board(), truth, session_poses(board(), 5));
  testing::hide_cross_views(views);
  CalibrationOptions o;
  o.board = board();
  o.min_shared_views = 1;
  const auto five = calibrate_rig(views.front, views.side, o);
  auto one_f = views.front, one_s = views.side;
  one_f.resize(17);  // 16 single-camera views + 1 shared
  one_s.resize(17);
  const auto one = calibrate_rig(one_f, one_s, o);
  EXPECT_GT(one.translation_sd_mm.maxCoeff(), 1.5 * five.translation_sd_mm.maxCoeff());
  o.max_translation_sd_mm =
      0.5 * (one.translation_sd_mm.maxCoeff() + five.translation_sd_mm.maxCoeff());
  try {
    calibrate_rig(one_f, one_s, o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not constrained"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("more views"), std::string::npos);
  }
  EXPECT_NO_THROW(calibrate_rig(views.front, views.side, o));  // five shared views suffice
}

TEST(CalibrateRig, BadInputIsRejected) {
  const cv::Mat img(480, 640, CV_8UC3, cv::Scalar::all(128));
  EXPECT_THROW(calibrate_rig({img}, {img, img}), std::invalid_argument);
  EXPECT_THROW(calibrate_rig({}, {}), std::invalid_argument);
  EXPECT_THROW(calibrate_rig({img, cv::Mat(10, 10, CV_8UC3)}, {img, img}), std::invalid_argument);
  CalibrationOptions o;
  o.board.cols = o.board.rows = 6;
  EXPECT_THROW(calibrate_rig({img}, {img}, o), std::invalid_argument);
  EXPECT_THROW(find_board(cv::Mat(), board()), std::invalid_argument);
  EXPECT_FALSE(find_board(img, board()).has_value());  // a blank image shows no board
  EXPECT_THROW(calibrate_rig({img, img, img, img}, {img, img, img, img}), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::capture
