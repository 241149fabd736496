#include "sim/sim_camera.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "capture/pair_capture.h"
#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::sim {
namespace {

TEST(SimCamera, StreamsRenderedHeadAtItsRate) {
  register_sim_cameras();
  auto cam = capture::open_camera("sim:3/front");
  EXPECT_EQ(cam->name(), "sim:3/front");
  cam->start({"BGR3", 320, 240, 30});
  std::vector<capture::Frame> frames;
  for (int i = 0; i < 6; ++i) {
    auto r = cam->next_frame(1.0);
    ASSERT_EQ(r.status, capture::FrameStatus::Ok) << r.message;
    frames.push_back(r.frame);
  }
  for (size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].sequence, frames[i - 1].sequence + 1);
    EXPECT_NEAR(frames[i].timestamp_s - frames[i - 1].timestamp_s, 1.0 / 30, 0.002);
  }
  const cv::Mat& img = frames.back().image;
  ASSERT_EQ(img.size(), cv::Size(320, 240));
  // The head covers the centre; the corner is the plain background.
  EXPECT_GT(cv::norm(img.at<cv::Vec3b>(120, 160), img.at<cv::Vec3b>(2, 2)), 30.0);
  EXPECT_LE(frames.back().timestamp_s, capture::monotonic_now_s() + 0.002);
}

TEST(SimCamera, BadIdsAndModesAreRejected) {
  register_sim_cameras();
  EXPECT_THROW(capture::open_camera("sim:x/front"), std::runtime_error);
  EXPECT_THROW(capture::open_camera("sim:1/top"), std::runtime_error);
  EXPECT_THROW(capture::open_camera("sim:1"), std::runtime_error);
  auto cam = capture::open_camera("sim:1/side");
  EXPECT_THROW(cam->start({"MJPG", 640, 480, 30}), std::runtime_error);
  EXPECT_THROW(cam->start({"BGR3", 800, 600, 30}), std::runtime_error);
  EXPECT_THROW(cam->next_frame(0.1), std::runtime_error);  // not started
  SimCameraOptions o;
  o.cycle_frames = 0;
  EXPECT_THROW(open_sim_camera(o), std::invalid_argument);
}

// reopen_camera: a device that is not there, or a mode it does not offer, gives null (still
// gone, try again later); one that is there comes back started in the mode asked.
TEST(SimCamera, ReopenGivesNullWhileGoneAndAStartedCameraWhenBack) {
  register_sim_cameras();
  EXPECT_EQ(capture::reopen_camera("sim:x/front", {"BGR3", 640, 480, 30}), nullptr);
  EXPECT_EQ(capture::reopen_camera("sim:1/side", {"MJPG", 640, 480, 30}), nullptr);
  auto cam = capture::reopen_camera("sim:1/side", {"BGR3", 640, 480, 30});
  ASSERT_NE(cam, nullptr);
  const capture::FrameResult r = cam->next_frame(2.0);
  EXPECT_EQ(r.status, capture::FrameStatus::Ok);
  EXPECT_EQ(r.frame.image.cols, 640);
}

TEST(SimCamera, PairOfSimCamerasHasTheRigPhaseAsSkew) {
  register_sim_cameras();
  capture::PairCaptureOptions o;
  o.width = 320;
  o.height = 240;
  capture::PairCapture pc("sim:2/front", "sim:2/side", o);
  ASSERT_TRUE(pc.take_pair(3.0).has_value());
  const auto pair = pc.take_pair(1.0);
  ASSERT_TRUE(pair.has_value());
  EXPECT_NEAR(pair->skew_s, 0.007, 0.0015);  // side clock 7 ms behind, +-0.5 ms jitter each
  EXPECT_GT(cv::norm(pair->front.image, pair->side.image, cv::NORM_L1), 0.0);  // two views
}

constexpr double kDeg = 3.14159265358979323846 / 180;

// The next frame of `cam` whose sequence is `residue` modulo `cycle` (at most cycle frames away).
capture::Frame frame_at(capture::Camera& cam, int cycle, int residue) {
  for (int i = 0; i <= 2 * cycle; ++i) {
    auto r = cam.next_frame(1.0);
    EXPECT_EQ(r.status, capture::FrameStatus::Ok) << r.message;
    if (r.status == capture::FrameStatus::Ok &&
        r.frame.sequence % static_cast<std::uint64_t>(cycle) == static_cast<std::uint64_t>(residue))
      return r.frame;
  }
  ADD_FAILURE() << "no frame with sequence " << residue << " mod " << cycle;
  return {};
}

// Whether pixel (c, r) of a plain-background sim frame shows the head.
bool on_head(const cv::Mat& img, int c, int r) {
  if (c < 0 || r < 0 || c >= img.cols || r >= img.rows) return false;
  return cv::norm(img.at<cv::Vec3b>(r, c), cv::Vec3b(200, 200, 200)) > 30.0;
}

TEST(SimCamera, HeadRotationIsTheLoopsYawAndPitch) {
  SimCameraOptions o;
  o.motion_deg = 20;
  o.cycle_frames = 4;
  for (std::uint64_t seq : {1u, 5u}) {  // sin(pi/2) = 1, and the loop repeats
    const Eigen::AngleAxisd a(sim_head_rotation(o, seq));
    EXPECT_NEAR(a.angle(), 20 * kDeg, 1e-9);
    EXPECT_NEAR(a.axis().dot(Eigen::Vector3d::UnitY()), 1.0, 1e-9);  // nose toward head +x
  }
  EXPECT_NEAR(Eigen::AngleAxisd(sim_head_rotation(o, 0)).angle(), 0.0, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(sim_head_rotation(o, 3)).angle(), 20 * kDeg, 1e-9);  // -20 yaw
  EXPECT_NEAR(Eigen::AngleAxisd(sim_head_rotation(o, 3)).axis().y(), -1.0, 1e-9);

  o.motion_deg = 0;
  o.pitch_deg = 10;
  o.cycle_frames = 8;  // pitch = 10 sin(4 pi k / 8): +10 at k = 1
  const Eigen::Matrix3d p = sim_head_rotation(o, 1);
  const Eigen::AngleAxisd a(p);
  EXPECT_NEAR(a.angle(), 10 * kDeg, 1e-9);
  EXPECT_NEAR(a.axis().dot(-Eigen::Vector3d::UnitX()), 1.0, 1e-9);
  EXPECT_GT((p * Eigen::Vector3d(0, 0, 100)).y(), 15.0);  // pitch > 0 lifts the nose

  // The truth's cameras carry the same P: R_true = R_nominal * P for both, translation kept.
  const capture::RigCalibration nominal = capture::ideal_rig(640, 480, 1.6);
  const capture::RigCalibration truth = sim_camera_rig(o, 640, 480, 1);
  for (auto [n, t] : {std::pair{&nominal.front, &truth.front}, {&nominal.side, &truth.side}}) {
    const Eigen::Matrix3d pn = n->cam_from_head.linear().transpose() * t->cam_from_head.linear();
    EXPECT_LT((pn - p).norm(), 1e-9);
    EXPECT_LT((n->cam_from_head.translation() - t->cam_from_head.translation()).norm(), 1e-9);
  }

  // Yaw and pitch together: P = Rx(-pitch) Ry(yaw), the same P for the side camera (its roll).
  o.motion_deg = 10;
  o.pitch_deg = 12;  // k = 1 of 8: yaw 10 sin(pi/4), pitch 12
  const Eigen::Matrix3d both = sim_head_rotation(o, 1);
  const Eigen::Matrix3d want = (Eigen::AngleAxisd(-12 * kDeg, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(10 * std::sin(3.14159265358979323846 / 4) * kDeg,
                                                  Eigen::Vector3d::UnitY()))
                                   .toRotationMatrix();
  EXPECT_LT((both - want).norm(), 1e-9);
  const capture::RigCalibration turned = sim_camera_rig(o, 640, 480, 1);
  EXPECT_LT(
      (nominal.side.cam_from_head.linear().transpose() * turned.side.cam_from_head.linear() - want)
          .norm(),
      1e-9);

  // Beyond +-15 deg too (issue 18: +-25 yaw, +-15 pitch; the options allow 30 / 20).
  o.motion_deg = 30;
  o.pitch_deg = 20;
  o.cycle_frames = 16;  // k = 2: yaw 30 sin(pi/4), pitch 20
  const capture::RigCalibration big = sim_camera_rig(o, 1280, 720, 2);
  const Eigen::Matrix3d pb =
      capture::ideal_rig(1280, 720, 3.2).front.cam_from_head.linear().transpose() *
      big.front.cam_from_head.linear();
  EXPECT_LT((pb - sim_head_rotation(o, 2)).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(big.front.fx, 3.2);
}

// The truth is sim::true_rig with the front camera pitched and the side camera rolled by -pitch,
// and the camera's frames are that rig's sim::simulate_capture photos.
TEST(SimCamera, TruthIsTheTrueRigOfThePoseErrorsAndMatchesTheFrames) {
  SimCameraOptions o;
  o.subject = 2;
  o.motion_deg = 10;
  o.pitch_deg = 12;
  o.cycle_frames = 8;
  const Head head = make_head(o.subject);
  for (int k : {1, 3}) {  // yaw +-7.07, pitch +-12
    const double yaw = 10 * std::sin(2 * 3.14159265358979323846 * k / 8);
    const double pitch = 12 * std::sin(4 * 3.14159265358979323846 * k / 8);
    RigOptions ro;
    ro.width = 320;
    ro.height = 240;
    ro.px_per_mm *= 0.5;
    ro.front_error.yaw_deg = yaw;
    ro.front_error.pitch_deg = pitch;
    ro.side_error.yaw_deg = yaw;
    ro.side_error.roll_deg = -pitch;  // the side camera's roll for the same head pitch
    const capture::RigCalibration expected = true_rig(ro);
    const capture::RigCalibration truth = sim_camera_rig(o, 320, 240, k);
    EXPECT_LT((truth.front.cam_from_head.matrix() - expected.front.cam_from_head.matrix()).norm(),
              1e-9);
    EXPECT_LT((truth.side.cam_from_head.matrix() - expected.side.cam_from_head.matrix()).norm(),
              1e-9);
    EXPECT_DOUBLE_EQ(truth.front.fx, expected.front.fx);
    EXPECT_DOUBLE_EQ(truth.side.cy, expected.side.cy);

    const Capture photos = simulate_capture(head, ro);
    for (bool side : {false, true}) {
      SimCameraOptions co = o;
      co.side = side;
      auto cam = open_sim_camera(co);
      cam->start({"BGR3", 320, 240, 30});
      const capture::Frame f = frame_at(*cam, 8, k);
      ASSERT_FALSE(f.image.empty());
      const cv::Mat& want = side ? photos.side : photos.front;
      EXPECT_LT(cv::norm(f.image, want, cv::NORM_L1) / double(want.total()), 0.5)
          << (side ? "side" : "front") << " frame " << k;
    }
  }
}

// A nodding head (pitch 12, ideal orthographic rig): the nose tip projected through the truth is
// on the head in both frames, on the same row in both, and the side frame's profile passes there
// (the side camera rolls the right way).
TEST(SimCamera, NoddingHeadIsWhereTheTruthProjectsIt) {
  register_sim_cameras();
  const std::string query = "?yaw=0&pitch=12&frames=8";
  SimCameraOptions o;
  o.subject = 4;
  o.motion_deg = 0;
  o.pitch_deg = 12;
  o.cycle_frames = 8;
  const Eigen::Vector3d nose = make_head(o.subject).landmarks.at("nose_tip");
  const Eigen::Vector3d chin = make_head(o.subject).landmarks.at("chin");
  Eigen::Vector2d px[2], chin_px[2];
  for (int side = 0; side < 2; ++side) {
    auto cam = capture::open_camera("sim:4/" + std::string(side ? "side" : "front") + query);
    EXPECT_EQ(cam->name(), "sim:4/" + std::string(side ? "side" : "front") + query);
    cam->start({"BGR3", 640, 480, 30});
    const capture::Frame f = frame_at(*cam, 8, 1);  // pitch +12
    ASSERT_FALSE(f.image.empty());
    const capture::RigCalibration truth = sim_camera_rig(o, 640, 480, f.sequence);
    const capture::CameraModel& c = side ? truth.side : truth.front;
    px[side] = capture::project(c, nose);
    chin_px[side] = capture::project(c, chin);
    const int col = static_cast<int>(std::floor(px[side].x()));
    const int row = static_cast<int>(std::floor(px[side].y()));
    // The side view's nose tip is on the silhouette: look 2 px into the head (face on the left).
    EXPECT_TRUE(on_head(f.image, side ? col + 2 : col, row)) << (side ? "side" : "front");
    if (side) {
      int left = 0;  // the profile: first head pixel from the left on the nose's row
      while (left < f.image.cols && !on_head(f.image, left, row)) ++left;
      EXPECT_NEAR(left + 0.5, px[side].x(), 2.0);
      // The nose tip is the profile's leftmost point near its row only if the truth's pitch
      // is the picture's: rows a few mm away have the profile farther right.
      int left_above = 0;
      while (left_above < f.image.cols && !on_head(f.image, left_above, row - 16)) ++left_above;
      EXPECT_GT(left_above, left);
    }
  }
  EXPECT_NEAR(px[0].y(), px[1].y(), 1.5);  // seed 004 eq. 1: equal rows in both views
  EXPECT_NEAR(chin_px[0].y(), chin_px[1].y(), 1.5);
  // And the head did pitch: the nose stands higher than on the level rig.
  EXPECT_LT(px[0].y(), capture::project(capture::ideal_rig(640, 480, 1.6).front, nose).y() - 15);
}

TEST(SimCamera, QueryIdsSetTheMotion) {
  register_sim_cameras();
  auto plain = capture::open_camera("sim:1/front");
  EXPECT_EQ(plain->name(), "sim:1/front");
  auto moving = capture::open_camera("sim:1/side?yaw=25&pitch=-15&frames=60");
  EXPECT_EQ(moving->name(), "sim:1/side?yaw=25&pitch=-15&frames=60");
  moving->start({"BGR3", 320, 240, 30});
  auto r = moving->next_frame(1.0);
  ASSERT_EQ(r.status, capture::FrameStatus::Ok) << r.message;
  EXPECT_EQ(r.frame.image.size(), cv::Size(320, 240));
}

TEST(SimCamera, BadQueriesNameTheProblem) {
  register_sim_cameras();
  auto message = [](const std::string& id) -> std::string {
    try {
      capture::open_camera(id);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string bad_number = message("sim:1/front?yaw=abc");
  EXPECT_NE(bad_number.find("sim:1/front?yaw=abc"), std::string::npos) << bad_number;
  EXPECT_NE(bad_number.find("yaw"), std::string::npos) << bad_number;
  EXPECT_NE(bad_number.find("abc"), std::string::npos) << bad_number;
  const std::string unknown = message("sim:1/front?spin=3");
  EXPECT_NE(unknown.find("sim:1/front?spin=3"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("'spin'"), std::string::npos) << unknown;
  const std::string range = message("sim:1/front?pitch=40");
  EXPECT_NE(range.find("sim:1/front?pitch=40"), std::string::npos) << range;
  EXPECT_NE(range.find("pitch_deg must be in [-20, 20]"), std::string::npos) << range;
  EXPECT_NE(message("sim:1/front?yaw=31").find("motion_deg"), std::string::npos);
  EXPECT_NE(message("sim:1/front?frames=2.5").find("frames"), std::string::npos);
  EXPECT_NE(message("sim:1/front?frames=0").find("cycle_frames"), std::string::npos);
  EXPECT_NE(message("sim:1/front?yaw=").find("yaw"), std::string::npos);
  EXPECT_NE(message("sim:1/front?yaw=nan").find("yaw"), std::string::npos);
  EXPECT_NE(message("sim:1/front&yaw=3"), "no error");
  SimCameraOptions o;
  o.pitch_deg = -20.5;
  try {
    o.check();
    ADD_FAILURE() << "pitch_deg -20.5 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pitch_deg"), std::string::npos);
  }
}

}  // namespace
}  // namespace orthoface::sim
