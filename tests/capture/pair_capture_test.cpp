#include "capture/pair_capture.h"

#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

#include "tests/capture/fake_v4l2_env.h"
#include "tests/capture/test_camera.h"

namespace orthoface::capture {
namespace {

using namespace std::chrono_literals;

std::vector<Frame> stream(double fps, double offset, int n) {
  std::vector<Frame> v(n);
  for (int i = 0; i < n; ++i) v[i].timestamp_s = 10.0 + offset + i / fps, v[i].sequence = i;
  return v;
}

PairCaptureOptions small() {
  PairCaptureOptions o;
  o.width = 64;
  o.height = 48;
  o.reopen_interval_s = 0.05;
  return o;
}

TEST(PairFrames, PairsEqualRatesWithTheirOffset) {
  const auto pairs = pair_frames(stream(30, 0, 30), stream(30, 0.010, 30), 0.02);
  ASSERT_EQ(pairs.size(), 30u);
  for (size_t i = 0; i < pairs.size(); ++i) {
    EXPECT_EQ(pairs[i].front.sequence, i);
    EXPECT_EQ(pairs[i].side.sequence, i);
    EXPECT_NEAR(pairs[i].skew_s, 0.010, 1e-9);
  }
}

TEST(PairFrames, FasterCameraGivesItsNearestFrame) {
  const auto pairs = pair_frames(stream(30, 0.004, 30), stream(60, 0, 60), 0.02);
  ASSERT_EQ(pairs.size(), 30u);
  for (const FramePair& p : pairs) {
    EXPECT_LE(p.skew_s, 1.0 / 120 + 1e-9);
    EXPECT_NEAR(p.skew_s, 0.004, 1e-9);  // side frames at 0, 1/60, ...: nearest is 4 ms away
  }
}

TEST(PairFrames, DegenerateInputsGiveNoPairs) {
  EXPECT_TRUE(pair_frames(stream(30, 0, 10), {}, 0.02).empty());
  EXPECT_TRUE(pair_frames(stream(30, 0, 10), stream(30, 0.5, 10), 0.02).empty());  // too far
  EXPECT_THROW(pair_frames({}, {}, 0.0), std::invalid_argument);
}

TEST(PairCapture, BadInputIsRejected) {
  testing::test_camera("a");
  EXPECT_TRUE(same_device("/dev/video0", "/dev/./video0"));
  EXPECT_FALSE(same_device("/dev/video0", "/dev/video1"));
  EXPECT_THROW(PairCapture("test:a", "test:a", small()), std::invalid_argument);
  EXPECT_THROW(PairCapture("test:a", "/dev/video_orthoface_missing", small()), std::runtime_error);
  EXPECT_THROW(PairCapture("test:a", "test:nobody", small()), std::runtime_error);
  PairCaptureOptions bad = small();
  bad.fps = 0;
  EXPECT_THROW(PairCapture("test:a", "test:b", bad), std::invalid_argument);
  bad = small();
  bad.width = 800;  // a size the camera lacks
  testing::test_camera("b");
  EXPECT_THROW(PairCapture("test:a", "test:b", bad), std::runtime_error);
}

TEST(PairCapture, PairsTwoLiveCamerasAndCountsDrops) {
  testing::test_camera("f1")->offset_s = 0.0;
  auto side = testing::test_camera("s1");
  side->offset_s = 0.006;
  side->drop_every = 10;
  PairCapture pc("test:f1", "test:s1", small());
  std::this_thread::sleep_for(1200ms);
  const PairStats s = pc.stats();
  pc.stop();
  EXPECT_NEAR(s.fps_front, 30, 2);
  EXPECT_GT(s.frames_front, 30u);
  EXPECT_GT(s.pairs, 25u);
  EXPECT_NEAR(s.skew_mean_s, 0.006, 0.001);
  EXPECT_LE(s.skew_max_s, 0.0061);
  EXPECT_GE(s.dropped_side, 2u);  // every 10th sequence number skipped
  EXPECT_EQ(s.dropped_front, 0u);
  EXPECT_GE(s.unpaired, 2u);  // front frames whose side partner was dropped
  EXPECT_TRUE(s.front_connected && s.side_connected);
}

TEST(PairCapture, UnplugReplugKeepsTakenPairs) {
  testing::test_camera("f2");
  auto side = testing::test_camera("s2");
  PairCapture pc("test:f2", "test:s2", small());
  const auto first = pc.take_pair(1.0);
  ASSERT_TRUE(first.has_value());
  side->unplugged = true;
  std::this_thread::sleep_for(200ms);
  EXPECT_FALSE(pc.stats().side_connected);
  EXPECT_FALSE(pc.take_pair(0.2).has_value());  // no side frames: no pair
  const auto ev = pc.events();
  ASSERT_FALSE(ev.empty());
  EXPECT_NE(ev.front().find("side camera lost"), std::string::npos);
  side->unplugged = false;
  const auto second = pc.take_pair(2.0);
  ASSERT_TRUE(second.has_value());
  const auto taken = pc.taken();
  ASSERT_EQ(taken.size(), 2u);
  EXPECT_EQ(taken[0].front.timestamp_s, first->front.timestamp_s);
  EXPECT_GT(taken[1].front.timestamp_s, taken[0].front.timestamp_s);
  const PairStats s = pc.stats();
  EXPECT_EQ(s.disconnects, 1);
  EXPECT_EQ(s.reconnects, 1);
  EXPECT_TRUE(s.side_connected);
}

TEST(PairCapture, ThroughFakeV4l2WithUnplug) {
  RUN_IN_FAKE_V4L2_CHILD();
  PairCaptureOptions o;
  o.reopen_interval_s = 0.1;
  PairCapture pc("/dev/video42", "/dev/video43", o);
  const auto first = pc.take_pair(2.0);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->front.image.cols, 640);
  EXPECT_LT(first->skew_s, o.max_skew_s);
  const std::string unplug = testing::fake_ctl_dir() + "/unplug-video42";
  std::ofstream(unplug) << "1";
  std::this_thread::sleep_for(400ms);
  EXPECT_FALSE(pc.stats().front_connected);
  std::filesystem::remove(unplug);
  ASSERT_TRUE(pc.take_pair(3.0).has_value());
  EXPECT_EQ(pc.taken().size(), 2u);
  EXPECT_EQ(pc.stats().reconnects, 1);
}

}  // namespace
}  // namespace orthoface::capture
