#pragma once

#include <string>
#include <vector>

#include "capture/camera.h"

namespace orthoface::capture {

// Manual controls applied at start() where the device offers them (-1 = leave automatic).
struct V4l2Controls {
  int exposure_100us = -1;   // V4L2_CID_EXPOSURE_ABSOLUTE, units of 100 us
  int white_balance_k = -1;  // V4L2_CID_WHITE_BALANCE_TEMPERATURE, kelvin
  bool autofocus = false;    // V4L2_CID_FOCUS_AUTO (off: focus must not hunt between pairs)
};

// A V4L2 capture node driven by raw ioctls (linux/videodev2.h): mmap streaming with
// kBufferCount buffers (few buffers = low latency), MJPEG decoded by OpenCV or YUYV converted,
// kernel CLOCK_MONOTONIC timestamps. The constructor throws std::runtime_error naming the path
// when it is missing, is not a V4L2 device or cannot capture video.
class V4l2Camera : public Camera {
 public:
  static constexpr int kBufferCount = 3;
  explicit V4l2Camera(const std::string& path, const V4l2Controls& controls = {});
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  std::string name() const override { return path_; }
  std::string card() const { return card_; }  // driver's card name (QUERYCAP)
  std::vector<CameraFormat> formats() const override;
  void start(const CameraFormat& format) override;
  FrameResult next_frame(double timeout_s) override;
  void stop() override;

 private:
  struct Buffer {
    void* data = nullptr;
    size_t length = 0;
  };
  void map_buffers();
  void apply_controls();
  bool set_control(unsigned id, int value);
  bool decode(const Buffer& buffer, size_t bytes, cv::Mat& out) const;

  std::string path_;
  std::string card_;
  V4l2Controls controls_;
  int fd_ = -1;
  bool streaming_ = false;
  bool lost_ = false;
  unsigned pixelformat_ = 0;
  int width_ = 0, height_ = 0, stride_ = 0;
  std::vector<Buffer> buffers_;
};

// Every /dev/video0..63 that opens as a V4L2 capture device, with its decodable modes.
std::vector<DeviceInfo> list_v4l2_devices();

// "MJPG" from V4L2_PIX_FMT_MJPEG and back. fourcc_code throws std::invalid_argument unless the
// text has 4 characters.
std::string fourcc_name(unsigned fourcc);
unsigned fourcc_code(const std::string& name);

}  // namespace orthoface::capture
