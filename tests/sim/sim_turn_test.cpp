// The simulated camera's one-way turn (SimCameraOptions::turn): the head of the one-camera
// enrolment, looking at the camera and then turning to a full profile.
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "capture/camera.h"
#include "capture/camera_model.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_camera.h"

namespace orthoface::sim {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180;

// Every frame of one pass of the loop, by its position in the loop.
std::map<int, capture::Frame> one_pass(const SimCameraOptions& o, int width, int height) {
  auto cam = open_sim_camera(o);
  cam->start({"BGR3", width, height, 30});
  std::map<int, capture::Frame> frames;
  for (int i = 0; i < 4 * o.cycle_frames && static_cast<int>(frames.size()) < o.cycle_frames; ++i) {
    capture::FrameResult r = cam->next_frame(1.0);
    EXPECT_EQ(r.status, capture::FrameStatus::Ok) << r.message;
    if (r.status == capture::FrameStatus::Ok)
      frames[static_cast<int>(r.frame.sequence % o.cycle_frames)] = r.frame;
  }
  EXPECT_EQ(static_cast<int>(frames.size()), o.cycle_frames);
  return frames;
}

bool on_head(const cv::Mat& img, const Eigen::Vector2d& px) {
  const int c = static_cast<int>(std::floor(px.x())), r = static_cast<int>(std::floor(px.y()));
  if (c < 0 || r < 0 || c >= img.cols || r >= img.rows) return false;
  return cv::norm(img.at<cv::Vec3b>(r, c), cv::Vec3b(200, 200, 200)) > 30.0;
}

TEST(SimTurn, TruthIsTheRampToAFullProfile) {
  SimCameraOptions o;
  o.turn = true;
  o.motion_deg = -90;
  o.cycle_frames = 31;  // 3 degrees a frame
  for (std::uint64_t k = 0; k < 62; ++k) {
    const double yaw = -90.0 * static_cast<double>(k % 31) / 30;
    const Eigen::Matrix3d want = Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitY()).matrix();
    EXPECT_LT((sim_head_rotation(o, k) - want).norm(), 1e-9) << "frame " << k;
  }
  // The other way, as far as the rig's cameras turn.
  o.motion_deg = 45;
  EXPECT_LT(
      (sim_head_rotation(o, 30) - Eigen::AngleAxisd(45 * kDeg, Eigen::Vector3d::UnitY()).matrix())
          .norm(),
      1e-9);
}

// Past -45 degrees the frame is the side camera's: at -45 both ways of drawing it must give the
// same picture, and the truth must put the head's landmarks on the head in every frame.
TEST(SimTurn, FramesAreWhereTheTruthPutsTheHead) {
  SimCameraOptions o;
  o.subject = 3;
  o.turn = true;
  o.motion_deg = -90;
  o.cycle_frames = 5;  // 0, -22.5, -45, -67.5, -90
  const std::map<int, capture::Frame> frames = one_pass(o, 320, 240);
  ASSERT_EQ(frames.size(), 5u);
  RigOptions ro;
  ro.width = 320;
  ro.height = 240;
  ro.px_per_mm *= 0.5;
  ro.side_error.yaw_deg = 45;  // the side camera, turned to where the front one is at -45
  const Capture c = simulate_capture(make_head(o.subject), ro);
  EXPECT_LT(cv::norm(frames.at(2).image, c.side, cv::NORM_L1) / double(c.side.total()), 1.0);

  const Head head = make_head(o.subject);
  const Eigen::Vector3d nose = head.landmarks.at("nose_tip");
  double nose_x[5];
  for (const auto& [k, f] : frames) {
    const capture::RigCalibration truth = sim_camera_rig(o, 320, 240, f.sequence);
    for (const char* name : {"nose_tip", "chin"}) {
      // 2 px into the head: in profile the nose tip and chin are on the silhouette.
      const Eigen::Vector2d px = capture::project(truth.front, head.landmarks.at(name));
      EXPECT_TRUE(on_head(f.image, px + Eigen::Vector2d(2, 0))) << name << " in frame " << k;
    }
    nose_x[k] = capture::project(truth.front, nose).x();
  }
  // The nose moves one way, to the image left, as the head turns toward head -x.
  for (int k = 1; k < 5; ++k) EXPECT_LT(nose_x[k], nose_x[k - 1] - 3) << k;
  // In full profile the nose tip is the head's leftmost point on its row.
  const cv::Mat& profile = frames.at(4).image;
  const capture::RigCalibration truth = sim_camera_rig(o, 320, 240, frames.at(4).sequence);
  const Eigen::Vector2d tip = capture::project(truth.front, nose);
  int left = 0;
  while (left < profile.cols && !on_head(profile, {left + 0.5, tip.y()})) ++left;
  EXPECT_NEAR(left + 0.5, tip.x(), 2.0);
}

TEST(SimTurn, BadTurnsAreRefused) {
  SimCameraOptions o;
  o.turn = true;
  o.motion_deg = -90;
  EXPECT_NO_THROW(o.check());
  for (double bad : {-91.0, 46.0, std::nan("")}) {
    SimCameraOptions b = o;
    b.motion_deg = bad;
    EXPECT_THROW(b.check(), std::invalid_argument) << bad;
  }
  SimCameraOptions nod = o;
  nod.pitch_deg = 5;
  EXPECT_THROW(nod.check(), std::invalid_argument);
  SimCameraOptions side = o;
  side.side = true;
  EXPECT_THROW(side.check(), std::invalid_argument);
  SimCameraOptions one = o;
  one.cycle_frames = 1;
  EXPECT_THROW(one.check(), std::invalid_argument);
  EXPECT_THROW(sim_camera_rig(nod, 320, 240, 0), std::invalid_argument);
  EXPECT_THROW(sim_head_rotation(side, 0), std::invalid_argument);
  // The loop keeps its limit.
  SimCameraOptions loop;
  loop.motion_deg = -60;
  EXPECT_THROW(loop.check(), std::invalid_argument);

  register_sim_cameras();
  for (const char* id :
       {"sim:1/front?turn=-90&yaw=3", "sim:1/front?turn=-120", "sim:1/side?turn=-90",
        "sim:1/front?turn=-90&pitch=5", "sim:1/front?turn=x"}) {
    try {
      capture::open_camera(id);
      ADD_FAILURE() << id << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(id), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(capture::open_camera("sim:1/front?turn=-90&frames=46")->name(),
            "sim:1/front?turn=-90&frames=46");
}

}  // namespace
}  // namespace orthoface::sim
