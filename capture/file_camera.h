#pragma once
// A video file or an image sequence played as a camera, for trying the station without cameras
// and for replaying recorded sessions in tests: "file:PATH[?OPTIONS]".
//   PATH     a video file OpenCV's FFmpeg backend reads (.avi, .mp4, .mkv, ...), or an image
//            sequence as a printf pattern ("frames/%04d.png", OpenCV's CAP_IMAGES)
//   OPTIONS  `loop` (start again at the end instead of ending), `fps=N` (play at N frames per
//            second instead of the file's own rate; required for an image sequence, which has
//            none), joined by '&': "file:talk.mp4?loop&fps=15"
// Frames come at the file's pace: frame n is due n / fps after start(), and next_frame waits for
// it (or returns Timeout when it is further than the timeout). Timestamps are CLOCK_MONOTONIC
// seconds: start() + the frame's own time in the file (CAP_PROP_POS_MSEC, or n / fps when the
// file has none), continued across loops. The end of a file that does not loop is
// FrameStatus::Disconnected ("end of the file after N frames").

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/videoio.hpp>

#include "capture/camera.h"

namespace orthoface::capture {

class FileCamera : public Camera {
 public:
  // `id` is the whole "file:..." text. Throws std::runtime_error naming it when the options are
  // malformed, the file is missing or is not a video / image sequence OpenCV can read, it holds
  // no frame, or it has no frame rate and no fps= was given.
  explicit FileCamera(const std::string& id);
  FileCamera(const FileCamera&) = delete;
  FileCamera& operator=(const FileCamera&) = delete;

  std::string name() const override { return id_; }
  // One mode: the file's frame size at its rate, fourcc as the file says ("BGR3" when unknown).
  std::vector<CameraFormat> formats() const override { return {format_}; }
  // Throws std::runtime_error when `format`'s size is not the file's (any fps is taken as the
  // file's own: a file cannot play at another rate than the one it was opened with).
  void start(const CameraFormat& format) override;
  FrameResult next_frame(double timeout_s) override;
  void stop() override;

 private:
  void open_capture();
  bool read_next();  // the next frame into pending_ (false at the end of a file not looping)
  [[noreturn]] void fail(const std::string& what) const;

  std::string id_, path_;
  bool loop_ = false;
  double fps_ = 0;
  CameraFormat format_;
  cv::VideoCapture capture_;
  bool started_ = false;
  double start_s_ = 0;            // monotonic time of start()
  std::uint64_t delivered_ = 0;   // frames handed out since start()
  std::uint64_t in_pass_ = 0;     // frames read in the current pass through the file
  double pass_offset_s_ = 0;      // file time at which the current pass began
  double last_file_time_s_ = -1;  // file time of the last frame read in this pass
  bool has_pending_ = false;      // a frame read but not yet due
  Frame pending_;                 // its image and timestamp (= when it is due)
};

}  // namespace orthoface::capture
