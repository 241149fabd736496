#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/camera.h"
#include "capture/camera_model.h"

namespace orthoface::app {

// Writes a pair as DIR/front.png, DIR/side.png, DIR/pair.json (timestamps, sequence, skew), into a
// staging folder beside DIR first (io::temp_path_for), renamed to DIR when complete. Returns DIR.
// Throws std::runtime_error naming the file that failed; DIR must not exist yet.
std::string save_pair(const capture::FramePair& pair, const std::string& dir);

// Throws std::runtime_error when no display is available (DISPLAY / WAYLAND_DISPLAY unset), since
// OpenCV's window code would abort the process.
void require_display(const std::string& what);

// Writes frames to a V4L2 output device (v4l2loopback, a virtual webcam) as YUYV, which Chrome,
// Zoom and OBS accept; width and height must be even. Throws std::runtime_error naming the
// device when it is missing, not a video output, or rejects the format.
class V4l2Output {
 public:
  V4l2Output(const std::string& path, int width, int height);
  ~V4l2Output();
  V4l2Output(const V4l2Output&) = delete;
  V4l2Output& operator=(const V4l2Output&) = delete;
  void write(const cv::Mat& bgr);  // resized to the device size; throws on a write error

 private:
  std::string path_;
  int fd_ = -1, width_ = 0, height_ = 0;
  std::vector<unsigned char> yuyv_;
};

// The rig of a station: read from rig_file when given; for two sim: cameras the simulated rig
// they render through (true scale); otherwise none (reconstruct's documented default scale).
std::optional<capture::RigCalibration> station_rig(const std::string& rig_file,
                                                   const std::string& front_id,
                                                   const std::string& side_id, int width,
                                                   int height);

// Packs BGR (even width) into YUYV 4:2:2.
void bgr_to_yuyv(const cv::Mat& bgr, std::vector<unsigned char>& out);

}  // namespace orthoface::app
