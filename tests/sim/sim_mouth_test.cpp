// The talking sim head: sim::open_mouth and the simulated camera's mouth_mm.
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "capture/camera.h"
#include "capture/camera_model.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "sim/sim_camera.h"

namespace orthoface::sim {
namespace {

const Head& head3() {
  static const Head h = make_head(3);
  return h;
}

TEST(OpenMouth, LowersTheChinAndKeepsTheFaceAboveTheLips) {
  const Head& closed = head3();
  const Head open = open_mouth(closed, 10);
  const auto& c = closed.landmarks;
  const auto& o = open.landmarks;
  EXPECT_NEAR(c.at("chin").y() - o.at("chin").y(), 10.0, 1e-6);
  EXPECT_LT(o.at("chin").z(), c.at("chin").z());  // the jaw turns down and back
  EXPECT_GT(c.at("lip_lower").y() - o.at("lip_lower").y(), 3.0);
  for (const char* n :
       {"lip_upper", "nose_tip", "subnasale", "eye_left_center", "forehead_top", "ear_left_tragus"})
    EXPECT_LT((o.at(n) - c.at(n)).norm(), 1e-9) << n;
  // Above the lips' line nothing moves; the neck's base stays.
  const double stomion = 0.5 * (c.at("lip_upper").y() + c.at("lip_lower").y());
  double lowest = 1e9;
  for (const auto& v : closed.mesh.vertices) lowest = std::min(lowest, v.y());
  for (size_t i = 0; i < closed.mesh.vertices.size(); ++i) {
    const Eigen::Vector3d &a = closed.mesh.vertices[i], &b = open.mesh.vertices[i];
    if (a.y() > stomion + 0.5 || a.y() < lowest + 5) {
      ASSERT_LT((a - b).norm(), 1e-9) << i;
    }
  }
  EXPECT_EQ(open.mesh.triangles, closed.mesh.triangles);
  mesh::check_mesh(open.mesh, "open mouth");
  // The closed head's texture is left as it was; the open one shows the mouth's dark inside.
  EXPECT_EQ(cv::norm(closed.mesh.texture, make_head(3).mesh.texture, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(open.mesh.texture, closed.mesh.texture, cv::NORM_L1), 0.0);
  EXPECT_EQ(open_mouth(closed, 0).mesh.vertices, closed.mesh.vertices);
}

TEST(OpenMouth, TheFrontViewShowsADarkMouth) {
  RigOptions ro;
  const Capture shut = simulate_capture(head3(), ro);
  const Capture open = simulate_capture(open_mouth(head3(), 8), ro);
  // Between the lips, in the front photo: dark when open, lip coloured when shut.
  const auto& lu = shut.landmarks.at("lip_upper").front_px;
  const auto& ll = shut.landmarks.at("lip_lower").front_px;
  const cv::Point centre(int(0.5 * (lu.x() + ll.x())), int(0.5 * (lu.y() + ll.y())) + 3);
  const cv::Rect box(centre - cv::Point(6, 3), cv::Size(12, 6));
  auto luma = [&](const cv::Mat& img) {
    cv::Mat g;
    cv::cvtColor(img(box), g, cv::COLOR_BGR2GRAY);
    return cv::mean(g)[0];
  };
  EXPECT_GT(luma(shut.front), 60.0);
  EXPECT_LT(luma(open.front), 40.0);
  // The chin lower in the photo by the opening (1.6 px/mm).
  EXPECT_NEAR(open.landmarks.at("chin").front_px.y() - shut.landmarks.at("chin").front_px.y(),
              8 * ro.px_per_mm, 0.5);
}

TEST(OpenMouth, BadOpeningsAndHeadsWithoutLipsAreRefused) {
  EXPECT_THROW(open_mouth(head3(), -1), std::invalid_argument);
  EXPECT_THROW(open_mouth(head3(), kMaxMouthOpenMm + 1), std::invalid_argument);
  EXPECT_THROW(open_mouth(head3(), std::nan("")), std::invalid_argument);
  Head no_lips = head3();
  no_lips.landmarks.erase("lip_lower");
  EXPECT_THROW(open_mouth(no_lips, 5), std::invalid_argument);
}

TEST(SimCameraMouth, TheMouthOpensAndClosesThreeTimesALoop) {
  SimCameraOptions o;
  o.cycle_frames = 12;
  o.mouth_mm = 9;
  EXPECT_DOUBLE_EQ(sim_mouth_open_mm(o, 0), 0.0);
  EXPECT_NEAR(sim_mouth_open_mm(o, 2), 9.0, 1e-9);  // half of a 4-frame cycle
  EXPECT_NEAR(sim_mouth_open_mm(o, 4), 0.0, 1e-9);
  EXPECT_NEAR(sim_mouth_open_mm(o, 12 + 2), 9.0, 1e-9);  // looping
  o.mouth_mm = 0;
  EXPECT_DOUBLE_EQ(sim_mouth_open_mm(o, 2), 0.0);
  o.mouth_mm = 16;
  EXPECT_THROW(sim_mouth_open_mm(o, 0), std::invalid_argument);
  o.mouth_mm = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

TEST(SimCameraMouth, FramesShowTheMouthTheTruthSays) {
  register_sim_cameras();
  auto cam = capture::open_camera("sim:3/front?yaw=0&frames=4&mouth=8");
  cam->start({"BGR3", 640, 480, 30});
  std::map<int, cv::Mat> frames;
  for (int i = 0; i < 16 && frames.size() < 4; ++i) {
    capture::FrameResult r = cam->next_frame(1.0);
    ASSERT_EQ(r.status, capture::FrameStatus::Ok) << r.message;
    frames[static_cast<int>(r.frame.sequence % 4)] = r.frame.image;
  }
  ASSERT_EQ(frames.size(), 4u);
  SimCameraOptions o;
  o.subject = 3, o.motion_deg = 0, o.cycle_frames = 4, o.mouth_mm = 8;
  // Frame 0 shut, frame 2 open 8 mm: each the still photo of that head.
  RigOptions ro;
  for (int k : {0, 2}) {
    const Capture c = simulate_capture(open_mouth(head3(), sim_mouth_open_mm(o, k)), ro);
    EXPECT_LT(cv::norm(frames.at(k), c.front, cv::NORM_L1) / double(c.front.total()), 0.5) << k;
  }
  EXPECT_GT(cv::norm(frames.at(0), frames.at(2), cv::NORM_L1), 0.0);
  EXPECT_THROW(capture::open_camera("sim:3/front?mouth=20"), std::runtime_error);
  EXPECT_THROW(capture::open_camera("sim:3/front?mouth=wide"), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::sim
