#include "sim/sim_camera.h"

#include <gtest/gtest.h>

#include "capture/pair_capture.h"

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

}  // namespace
}  // namespace orthoface::sim
