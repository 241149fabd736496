#include "capture/file_camera.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "tests/common/test_data.h"

namespace orthoface::capture {
namespace {

namespace fs = std::filesystem;

// Frame i of every test clip: a uniform grey of 20 * i + 10 (distinct after JPEG coding).
cv::Mat clip_frame(int i) { return cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(20 * i + 10)); }
int grey_of(const cv::Mat& image) { return int(std::lround(cv::mean(image)[0])); }

// An MJPG AVI of `frames` frames at `fps`, written by OpenCV's own writer.
std::string write_clip(const fs::path& dir, int frames, double fps) {
  const std::string path = (dir / "clip.avi").string();
  cv::VideoWriter out(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                      cv::Size(64, 48));
  EXPECT_TRUE(out.isOpened());
  for (int i = 0; i < frames; ++i) out.write(clip_frame(i));
  return path;
}

std::string refusal(const std::string& id) {
  try {
    FileCamera camera(id);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "opened";
}

TEST(FileCamera, PlaysAVideoAtItsOwnRateThenEnds) {
  const std::string path = write_clip(testing::temp_dir("file_camera_clip"), 6, 20);
  const std::unique_ptr<Camera> camera = open_camera("file:" + path);
  ASSERT_EQ(camera->formats().size(), 1u);
  const CameraFormat f = camera->formats()[0];
  EXPECT_EQ(f.fourcc, "MJPG");
  EXPECT_EQ(f.width, 64);
  EXPECT_EQ(f.height, 48);
  EXPECT_DOUBLE_EQ(f.fps, 20);
  const double before = monotonic_now_s();
  camera->start(f);
  std::vector<double> stamps;
  for (int i = 0; i < 6; ++i) {
    const FrameResult r = camera->next_frame(1.0);
    ASSERT_EQ(r.status, FrameStatus::Ok) << i << ": " << r.message;
    EXPECT_EQ(r.frame.sequence, std::uint64_t(i));
    EXPECT_NEAR(grey_of(r.frame.image), 20 * i + 10, 3) << i;
    EXPECT_EQ(r.frame.image.type(), CV_8UC3);
    stamps.push_back(r.frame.timestamp_s);
  }
  // Frame i is stamped 0.05 i s after start() and is not handed out before that time.
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(stamps[size_t(i)] - stamps[0], 0.05 * i, 1e-3) << i;
  EXPECT_GE(stamps[0], before);
  EXPECT_GE(monotonic_now_s(), stamps[5]);
  const FrameResult end = camera->next_frame(1.0);
  EXPECT_EQ(end.status, FrameStatus::Disconnected);
  EXPECT_NE(end.message.find("end of the file after 6 frames"), std::string::npos) << end.message;
  camera->stop();
  camera->stop();  // idempotent
}

TEST(FileCamera, LoopsWithTimestampsRunningOn) {
  const std::string path = write_clip(testing::temp_dir("file_camera_loop"), 3, 50);
  FileCamera camera("file:" + path + "?loop&fps=100");
  EXPECT_DOUBLE_EQ(camera.formats()[0].fps, 100);
  camera.start(camera.formats()[0]);
  double previous = 0;
  for (int i = 0; i < 8; ++i) {
    const FrameResult r = camera.next_frame(1.0);
    ASSERT_EQ(r.status, FrameStatus::Ok) << i << ": " << r.message;
    EXPECT_NEAR(grey_of(r.frame.image), 20 * (i % 3) + 10, 3) << i;
    EXPECT_EQ(r.frame.sequence, std::uint64_t(i));
    if (i > 0) {
      EXPECT_GT(r.frame.timestamp_s, previous) << i;
    }
    previous = r.frame.timestamp_s;
  }
}

TEST(FileCamera, PlaysAnImageSequenceAtTheGivenRate) {
  const fs::path dir = testing::temp_dir("file_camera_images");
  for (int i = 1; i <= 4; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "f_%03d.png", i);
    cv::Mat grey;
    cv::extractChannel(clip_frame(i), grey, 0);
    cv::imwrite((dir / name).string(), i == 2 ? grey : clip_frame(i));  // a grey one among them
  }
  const std::string id = "file:" + (dir / "f_%03d.png").string() + "?fps=200";
  FileCamera camera(id);
  EXPECT_EQ(camera.name(), id);
  camera.start({"BGR3", 64, 48, 200});
  for (int i = 1; i <= 4; ++i) {
    const FrameResult r = camera.next_frame(1.0);
    ASSERT_EQ(r.status, FrameStatus::Ok) << i << ": " << r.message;
    EXPECT_EQ(grey_of(r.frame.image), 20 * i + 10) << i;
    EXPECT_EQ(r.frame.image.type(), CV_8UC3) << i;
  }
  EXPECT_EQ(camera.next_frame(1.0).status, FrameStatus::Disconnected);
}

TEST(FileCamera, AFrameNotYetDueIsATimeoutAndStaysPending) {
  const std::string path = write_clip(testing::temp_dir("file_camera_slow"), 3, 2);
  FileCamera camera("file:" + path);
  camera.start(camera.formats()[0]);
  ASSERT_EQ(camera.next_frame(1.0).status, FrameStatus::Ok);
  const FrameResult early = camera.next_frame(0.01);  // frame 1 is due 0.5 s after start
  EXPECT_EQ(early.status, FrameStatus::Timeout);
  const FrameResult due = camera.next_frame(1.0);
  ASSERT_EQ(due.status, FrameStatus::Ok) << due.message;
  EXPECT_EQ(due.frame.sequence, 1u);
  EXPECT_NEAR(grey_of(due.frame.image), 30, 3);
}

TEST(FileCamera, BadIdsFilesAndModesAreRefusedNamingTheCamera) {
  const fs::path dir = testing::temp_dir("file_camera_bad");
  const std::string clip = write_clip(dir, 2, 10);
  std::ofstream(dir / "text.avi") << "not a video\n";
  std::ofstream(dir / "empty.avi");
  const std::pair<std::string, std::string> cases[] = {
      {"file:" + (dir / "none.avi").string(), "no such file"},
      {"file:" + dir.string(), "no such file"},
      {"file:", "no file named"},
      {"file:" + (dir / "text.avi").string(), "not a video OpenCV can read"},
      {"file:" + (dir / "empty.avi").string(), "not a video OpenCV can read"},
      {"file:" + clip + "?speed=2", "unknown option 'speed=2'"},
      {"file:" + clip + "?fps=0", "fps= must be a number in (0, 1000]"},
      {"file:" + clip + "?fps=-5", "fps= must be"},
      {"file:" + clip + "?fps=12abc", "fps= must be"},
      {"file:" + clip + "?fps=nan", "fps= must be"},
      {"file:" + (dir / "x_%03d.png").string() + "?fps=10", "no image of the sequence"},
      {"file:" + (dir / "x_%03d.png").string(), "an image sequence has no frame rate"},
  };
  for (const auto& [id, expect] : cases) {
    const std::string message = refusal(id);
    EXPECT_NE(message.find("camera " + id + ": " + expect), std::string::npos) << id << "\n"
                                                                               << message;
  }
  FileCamera camera("file:" + clip);
  EXPECT_THROW(camera.next_frame(0.1), std::runtime_error);  // not started
  EXPECT_THROW(camera.start({"MJPG", 640, 480, 10}), std::runtime_error);
  EXPECT_THROW(open_camera("file:" + (dir / "none.avi").string()), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::capture
