#include "app/station_output.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "io/atomic_file.h"
#include "sim/sim_camera.h"

namespace orthoface::app {

std::string save_pair(const capture::FramePair& pair, const std::string& dir) {
  namespace fs = std::filesystem;
  if (fs::exists(dir)) throw std::runtime_error("pair folder " + dir + " already exists");
  const std::string tmp = io::temp_path_for(dir);
  try {
    fs::create_directories(tmp);
    // Through io: a full disk, even at the last flush, is an error, not a truncated pair.
    for (const auto& [name, frame] :
         {std::pair{"front.png", &pair.front}, {"side.png", &pair.side}})
      io::write_image_atomically(tmp + "/" + name, frame->image);
    char text[512];
    std::snprintf(
        text, sizeof(text),
        "{\n  \"front\": {\"timestamp_s\": %.6f, \"sequence\": %llu},\n"
        "  \"side\": {\"timestamp_s\": %.6f, \"sequence\": %llu},\n  \"skew_ms\": %.3f\n}\n",
        pair.front.timestamp_s, static_cast<unsigned long long>(pair.front.sequence),
        pair.side.timestamp_s, static_cast<unsigned long long>(pair.side.sequence),
        pair.skew_s * 1e3);
    io::write_text_atomically(tmp + "/pair.json", text);
    fs::rename(tmp, dir);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
  return dir;
}

std::optional<capture::RigCalibration> station_rig(const std::string& rig_file,
                                                   const std::string& front_id,
                                                   const std::string& side_id, int width,
                                                   int height) {
  if (!rig_file.empty()) return capture::read_rig(rig_file);
  if (front_id.rfind("sim:", 0) == 0 && side_id.rfind("sim:", 0) == 0) {
    // The sim cameras of a frame at rest (sequence 0: no head turn, whatever the motion): the
    // ideal rig scaled to the mode's size, as sim/sim_camera.cpp renders it.
    capture::RigCalibration rig = sim::sim_camera_rig(sim::SimCameraOptions{}, width, height, 0);
    rig.source = "sim";  // the nominal rig, not one frame's truth
    return rig;
  }
  return std::nullopt;
}

void require_display(const std::string& what) {
  const char* x = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  if ((!x || !*x) && (!w || !*w))
    throw std::runtime_error(what +
                             ": no display (DISPLAY is not set); use --output http:PORT "
                             "or v4l2:/dev/videoN on a headless machine");
}

void bgr_to_yuyv(const cv::Mat& bgr, std::vector<unsigned char>& out) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);
  out.resize(size_t(bgr.cols) * bgr.rows * 2);
  for (int r = 0; r < yuv.rows; ++r) {
    const cv::Vec3b* p = yuv.ptr<cv::Vec3b>(r);
    unsigned char* d = out.data() + size_t(r) * yuv.cols * 2;
    for (int c = 0; c + 1 < yuv.cols; c += 2) {
      d[2 * c] = p[c][0];
      d[2 * c + 1] = static_cast<unsigned char>((p[c][1] + p[c + 1][1]) / 2);
      d[2 * c + 2] = p[c + 1][0];
      d[2 * c + 3] = static_cast<unsigned char>((p[c][2] + p[c + 1][2]) / 2);
    }
  }
}

V4l2Output::V4l2Output(const std::string& path, int width, int height)
    : path_(path), width_(width), height_(height) {
  if (width % 2 || height % 2 || width <= 0 || height <= 0)
    throw std::invalid_argument("v4l2 output " + path + ": width and height must be even");
  fd_ = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error("v4l2 output " + path + ": " + std::strerror(errno));
  v4l2_capability cap{};
  const unsigned caps =
      ioctl(fd_, VIDIOC_QUERYCAP, &cap) == 0
          ? ((cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities)
          : 0;
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_OUTPUT;
  fmt.fmt.pix.width = width;
  fmt.fmt.pix.height = height;
  fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  fmt.fmt.pix.bytesperline = width * 2;
  fmt.fmt.pix.sizeimage = width * height * 2;
  fmt.fmt.pix.colorspace = V4L2_COLORSPACE_SRGB;
  if (!(caps & V4L2_CAP_VIDEO_OUTPUT) || ioctl(fd_, VIDIOC_S_FMT, &fmt) != 0) {
    ::close(fd_);
    throw std::runtime_error("v4l2 output " + path + ": not a video output device accepting YUYV " +
                             std::to_string(width) + "x" + std::to_string(height) +
                             " (is it a v4l2loopback device?)");
  }
}

V4l2Output::~V4l2Output() {
  if (fd_ >= 0) ::close(fd_);
}

void V4l2Output::write(const cv::Mat& bgr) {
  cv::Mat sized = bgr;
  if (bgr.cols != width_ || bgr.rows != height_) cv::resize(bgr, sized, {width_, height_});
  bgr_to_yuyv(sized, yuyv_);
  if (::write(fd_, yuyv_.data(), yuyv_.size()) != static_cast<ssize_t>(yuyv_.size()))
    throw std::runtime_error("v4l2 output " + path_ + ": write failed: " + std::strerror(errno));
}

}  // namespace orthoface::app
