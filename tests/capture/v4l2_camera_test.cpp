// V4L2 backend against the fake device (tests/capture/fake_v4l2), which follows the V4L2 rules
// checked by v4l2-compliance; the production code runs unchanged on top of it.
#include "capture/v4l2_camera.h"

#include <fstream>

#include <gtest/gtest.h>

#include "tests/capture/fake_v4l2_env.h"

namespace orthoface::capture {
namespace {

using orthoface::testing::fake_ctl_dir;
using orthoface::testing::under_fake_v4l2;

void touch(const std::string& name) { std::ofstream(fake_ctl_dir() + "/" + name) << "1"; }

std::vector<Frame> grab(Camera& cam, int n) {
  std::vector<Frame> frames;
  for (int i = 0; i < n; ++i) {
    FrameResult r = cam.next_frame(2.0);
    EXPECT_EQ(r.status, FrameStatus::Ok) << r.message;
    if (r.status != FrameStatus::Ok) break;
    frames.push_back(std::move(r.frame));
  }
  return frames;
}

// Test pattern of the fake: 8 vertical bars, white first, red (BGR 0,0,255) sixth.
void expect_test_pattern(const cv::Mat& img) {
  ASSERT_EQ(img.type(), CV_8UC3);
  const cv::Vec3b white = img.at<cv::Vec3b>(20, img.cols / 16);
  const cv::Vec3b red = img.at<cv::Vec3b>(20, img.cols * 11 / 16);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(white[c], 255, 20);
  EXPECT_NEAR(red[0], 0, 30);
  EXPECT_NEAR(red[1], 0, 30);
  EXPECT_NEAR(red[2], 255, 30);
}

void expect_stream(const std::string& fourcc) {
  V4l2Camera cam("/dev/video42");
  cam.start({fourcc, 640, 480, 30});
  const double t0 = monotonic_now_s();
  const std::vector<Frame> frames = grab(cam, 8);
  ASSERT_EQ(frames.size(), 8u);
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].image.cols, 640);
    EXPECT_EQ(frames[i].image.rows, 480);
    EXPECT_GT(frames[i].timestamp_s, t0 - 0.5);  // kernel clock = CLOCK_MONOTONIC
    EXPECT_LE(frames[i].timestamp_s, monotonic_now_s());
    if (i > 0) {
      EXPECT_GT(frames[i].sequence, frames[i - 1].sequence);
      EXPECT_NEAR(frames[i].timestamp_s - frames[i - 1].timestamp_s,
                  (frames[i].sequence - frames[i - 1].sequence) / 30.0, 0.03);
    }
  }
  expect_test_pattern(frames.back().image);
  cam.stop();
}

TEST(V4l2Camera, NonexistentDeviceNamesIt) {
  try {
    V4l2Camera cam("/dev/video_orthoface_missing");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/video_orthoface_missing"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no such device"), std::string::npos);
  }
}

TEST(V4l2Camera, NotAV4l2DeviceIsRejected) {
  EXPECT_THROW(V4l2Camera("/dev/null"), std::runtime_error);
  EXPECT_THROW(open_camera("/dev/null"), std::runtime_error);
}

TEST(V4l2Camera, FourccRoundTripAndBadText) {
  EXPECT_EQ(fourcc_name(fourcc_code("MJPG")), "MJPG");
  EXPECT_THROW(fourcc_code("MJP"), std::invalid_argument);
}

TEST(V4l2Camera, ListsFormatsOfFake) {
  RUN_IN_FAKE_V4L2_CHILD();
  V4l2Camera cam("/dev/video42");
  EXPECT_EQ(cam.card(), "orthoface fake camera");
  const auto formats = cam.formats();
  EXPECT_EQ(formats.size(), 12u);  // {YUYV, MJPG} x 3 sizes x {30, 15} fps
  const CameraFormat f = choose_format(formats, 640, 480, 30, cam.name());
  EXPECT_EQ(f.fourcc, "MJPG");
  EXPECT_DOUBLE_EQ(f.fps, 30.0);
  bool listed = false;
  for (const DeviceInfo& d : list_devices()) listed |= d.id == "/dev/video43";
  EXPECT_TRUE(listed);
}

TEST(V4l2Camera, StreamsYuyv) {
  RUN_IN_FAKE_V4L2_CHILD();
  expect_stream("YUYV");
}

TEST(V4l2Camera, StreamsMjpeg) {
  RUN_IN_FAKE_V4L2_CHILD();
  expect_stream("MJPG");
}

TEST(V4l2Camera, FormatTheCameraLacksIsAnError) {
  RUN_IN_FAKE_V4L2_CHILD();
  V4l2Camera cam("/dev/video42");
  try {
    cam.start({"MJPG", 800, 600, 30});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/video42"), std::string::npos);
  }
  EXPECT_THROW(cam.start({"RGB4", 640, 480, 30}), std::runtime_error);
  EXPECT_THROW(choose_format(cam.formats(), 800, 600, 30, cam.name()), std::runtime_error);
  EXPECT_THROW(choose_format({}, 640, 480, 30, cam.name()), std::runtime_error);
}

TEST(V4l2Camera, SameDeviceTwiceCannotStreamTwice) {
  RUN_IN_FAKE_V4L2_CHILD();
  V4l2Camera a("/dev/video42"), b("/dev/video42");
  a.start({"YUYV", 640, 480, 30});
  EXPECT_THROW(b.start({"YUYV", 640, 480, 30}), std::runtime_error);  // EBUSY
  EXPECT_EQ(grab(a, 2).size(), 2u);
}

TEST(V4l2Camera, UnplugIsReportedAndReplugReopens) {
  RUN_IN_FAKE_V4L2_CHILD();
  auto cam = std::make_unique<V4l2Camera>("/dev/video43");
  cam->start({"MJPG", 640, 480, 30});
  ASSERT_EQ(grab(*cam, 2).size(), 2u);
  touch("unplug-video43");
  FrameResult r = cam->next_frame(1.0);
  EXPECT_EQ(r.status, FrameStatus::Disconnected);
  EXPECT_NE(r.message.find("/dev/video43"), std::string::npos);
  EXPECT_THROW(V4l2Camera("/dev/video43"), std::runtime_error);  // gone while unplugged
  std::filesystem::remove(fake_ctl_dir() + "/unplug-video43");
  cam = std::make_unique<V4l2Camera>("/dev/video43");
  cam->start({"MJPG", 640, 480, 30});
  EXPECT_EQ(grab(*cam, 2).size(), 2u);
}

TEST(V4l2Camera, IoErrorIsReported) {
  RUN_IN_FAKE_V4L2_CHILD();
  V4l2Camera cam("/dev/video42");
  cam.start({"YUYV", 320, 240, 15});
  ASSERT_EQ(grab(cam, 1).size(), 1u);
  touch("eio-video42");
  const FrameResult r = cam.next_frame(1.0);
  EXPECT_EQ(r.status, FrameStatus::Disconnected);
  EXPECT_NE(r.message.find("Input/output error"), std::string::npos) << r.message;
}

TEST(V4l2Camera, NextFrameBeforeStartIsAnError) {
  RUN_IN_FAKE_V4L2_CHILD();
  V4l2Camera cam("/dev/video42");
  EXPECT_THROW(cam.next_frame(0.1), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::capture
