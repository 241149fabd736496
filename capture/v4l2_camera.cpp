#include "capture/v4l2_camera.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file.h"

namespace orthoface::capture {
namespace {

// ioctl restarted on EINTR, as every V4L2 client must.
int xioctl(int fd, unsigned long request, void* arg) {
  int r;
  do r = ioctl(fd, request, arg);
  while (r == -1 && errno == EINTR);
  return r;
}

bool decodable(unsigned pixelformat) {
  return pixelformat == V4L2_PIX_FMT_MJPEG || pixelformat == V4L2_PIX_FMT_JPEG ||
         pixelformat == V4L2_PIX_FMT_YUYV;
}

std::vector<double> frame_rates(int fd, unsigned pixelformat, int w, int h) {
  std::vector<double> rates;
  v4l2_frmivalenum iv{};
  iv.pixel_format = pixelformat;
  iv.width = w;
  iv.height = h;
  for (iv.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &iv) == 0; ++iv.index) {
    if (iv.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      if (iv.discrete.numerator > 0)
        rates.push_back(double(iv.discrete.denominator) / iv.discrete.numerator);
    } else {  // stepwise / continuous: the fastest rate stands for the range
      if (iv.stepwise.min.numerator > 0)
        rates.push_back(double(iv.stepwise.min.denominator) / iv.stepwise.min.numerator);
      break;
    }
  }
  if (rates.empty()) rates.push_back(30.0);  // drivers without ENUM_FRAMEINTERVALS
  return rates;
}

std::vector<std::pair<int, int>> frame_sizes(int fd, unsigned pixelformat) {
  std::vector<std::pair<int, int>> sizes;
  v4l2_frmsizeenum fs{};
  fs.pixel_format = pixelformat;
  for (fs.index = 0; xioctl(fd, VIDIOC_ENUM_FRAMESIZES, &fs) == 0; ++fs.index) {
    if (fs.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      sizes.emplace_back(fs.discrete.width, fs.discrete.height);
      continue;
    }
    // Stepwise / continuous: offer the common sizes inside the range.
    for (auto [w, h] : {std::pair{320, 240}, {640, 480}, {1280, 720}, {1920, 1080}})
      if (w >= int(fs.stepwise.min_width) && w <= int(fs.stepwise.max_width) &&
          h >= int(fs.stepwise.min_height) && h <= int(fs.stepwise.max_height))
        sizes.emplace_back(w, h);
    break;
  }
  return sizes;
}

std::vector<CameraFormat> enumerate_formats(int fd) {
  std::vector<CameraFormat> out;
  v4l2_fmtdesc desc{};
  desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  for (desc.index = 0; xioctl(fd, VIDIOC_ENUM_FMT, &desc) == 0; ++desc.index) {
    if (!decodable(desc.pixelformat)) continue;
    for (auto [w, h] : frame_sizes(fd, desc.pixelformat))
      for (double fps : frame_rates(fd, desc.pixelformat, w, h))
        out.push_back({fourcc_name(desc.pixelformat), w, h, fps});
  }
  return out;
}

std::string errno_text(int e) { return std::string(std::strerror(e)); }

}  // namespace

std::string fourcc_name(unsigned f) {
  std::string s(4, ' ');
  for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((f >> (8 * i)) & 0xff);
  return s;
}

unsigned fourcc_code(const std::string& name) {
  if (name.size() != 4)
    throw std::invalid_argument("fourcc_code: expected 4 characters, got '" + name + "'");
  return v4l2_fourcc(name[0], name[1], name[2], name[3]);
}

V4l2Camera::V4l2Camera(const std::string& path, const V4l2Controls& controls)
    : path_(path), controls_(controls) {
  fd_ = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int e = errno;
    throw std::runtime_error("camera " + path + ": " +
                             (e == ENOENT ? std::string("no such device") : errno_text(e)));
  }
  v4l2_capability cap{};
  if (xioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
    const int e = errno;
    ::close(fd_);
    throw std::runtime_error("camera " + path + ": not a V4L2 device (" + errno_text(e) + ")");
  }
  const unsigned caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  card_ = reinterpret_cast<const char*>(cap.card);
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE) || !(caps & V4L2_CAP_STREAMING)) {
    ::close(fd_);
    throw std::runtime_error("camera " + path + " (" + card_ +
                             "): not a video capture device with streaming I/O");
  }
}

V4l2Camera::~V4l2Camera() {
  stop();
  if (fd_ >= 0) ::close(fd_);
}

std::vector<CameraFormat> V4l2Camera::formats() const { return enumerate_formats(fd_); }

void V4l2Camera::start(const CameraFormat& format) {
  if (streaming_) throw std::runtime_error("camera " + path_ + ": already started");
  bool offered = false;
  for (const CameraFormat& f : formats())
    offered |= f.fourcc == format.fourcc && f.width == format.width && f.height == format.height &&
               (format.fps <= 0 || std::abs(f.fps - format.fps) < 0.01);
  if (!offered)
    throw std::runtime_error("camera " + path_ + ": does not offer " + format.fourcc + " " +
                             std::to_string(format.width) + "x" + std::to_string(format.height) +
                             " at " + std::to_string(format.fps) + " fps");
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = format.width;
  fmt.fmt.pix.height = format.height;
  fmt.fmt.pix.pixelformat = fourcc_code(format.fourcc);
  fmt.fmt.pix.field = V4L2_FIELD_NONE;
  if (xioctl(fd_, VIDIOC_S_FMT, &fmt) != 0)
    throw std::runtime_error("camera " + path_ + ": VIDIOC_S_FMT failed: " + errno_text(errno));
  if (int(fmt.fmt.pix.width) != format.width || int(fmt.fmt.pix.height) != format.height ||
      fmt.fmt.pix.pixelformat != fourcc_code(format.fourcc))
    throw std::runtime_error("camera " + path_ + ": driver changed the requested format to " +
                             fourcc_name(fmt.fmt.pix.pixelformat) + " " +
                             std::to_string(fmt.fmt.pix.width) + "x" +
                             std::to_string(fmt.fmt.pix.height));
  pixelformat_ = fmt.fmt.pix.pixelformat;
  width_ = fmt.fmt.pix.width;
  height_ = fmt.fmt.pix.height;
  stride_ = fmt.fmt.pix.bytesperline ? int(fmt.fmt.pix.bytesperline) : width_ * 2;
  if (format.fps > 0) {
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    parm.parm.capture.timeperframe.numerator = 1000;
    parm.parm.capture.timeperframe.denominator = unsigned(std::lround(format.fps * 1000));
    xioctl(fd_, VIDIOC_S_PARM, &parm);  // optional: some drivers have a fixed rate
  }
  apply_controls();
  map_buffers();
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (xioctl(fd_, VIDIOC_STREAMON, &type) != 0) {
    const int e = errno;
    stop();
    throw std::runtime_error("camera " + path_ + ": VIDIOC_STREAMON failed: " + errno_text(e));
  }
  streaming_ = true;
}

void V4l2Camera::map_buffers() {
  v4l2_requestbuffers req{};
  req.count = kBufferCount;
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (xioctl(fd_, VIDIOC_REQBUFS, &req) != 0 || req.count < 2)
    throw std::runtime_error("camera " + path_ +
                             ": cannot allocate mmap buffers: " + errno_text(errno));
  for (unsigned i = 0; i < req.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (xioctl(fd_, VIDIOC_QUERYBUF, &b) != 0)
      throw std::runtime_error("camera " + path_ +
                               ": VIDIOC_QUERYBUF failed: " + errno_text(errno));
    void* p = mmap(nullptr, b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
    if (p == MAP_FAILED)
      throw std::runtime_error("camera " + path_ + ": mmap failed: " + errno_text(errno));
    buffers_.push_back({p, b.length});
    if (xioctl(fd_, VIDIOC_QBUF, &b) != 0)
      throw std::runtime_error("camera " + path_ + ": VIDIOC_QBUF failed: " + errno_text(errno));
  }
}

bool V4l2Camera::set_control(unsigned id, int value) {
  v4l2_queryctrl q{};
  q.id = id;
  if (xioctl(fd_, VIDIOC_QUERYCTRL, &q) != 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED)) return false;
  v4l2_control c{};
  c.id = id;
  c.value = std::clamp(value, q.minimum, q.maximum);
  return xioctl(fd_, VIDIOC_S_CTRL, &c) == 0;
}

void V4l2Camera::apply_controls() {
  set_control(V4L2_CID_FOCUS_AUTO, controls_.autofocus ? 1 : 0);
  if (controls_.exposure_100us >= 0 && set_control(V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL))
    set_control(V4L2_CID_EXPOSURE_ABSOLUTE, controls_.exposure_100us);
  if (controls_.white_balance_k >= 0 && set_control(V4L2_CID_AUTO_WHITE_BALANCE, 0))
    set_control(V4L2_CID_WHITE_BALANCE_TEMPERATURE, controls_.white_balance_k);
}

bool V4l2Camera::decode(const Buffer& buffer, size_t bytes, cv::Mat& out) const {
  if (pixelformat_ == V4L2_PIX_FMT_YUYV) {
    if (bytes < size_t(stride_) * height_) return false;
    const cv::Mat yuyv(height_, width_, CV_8UC2, buffer.data, stride_);
    cv::cvtColor(yuyv, out, cv::COLOR_YUV2BGR_YUYV);
    return true;
  }
  const cv::Mat jpeg(1, int(std::min(bytes, buffer.length)), CV_8U, buffer.data);
  // Copies: the buffer goes back to the driver.
  out = io::imdecode_accepted(jpeg, cv::IMREAD_COLOR);
  return !out.empty() && out.cols == width_ && out.rows == height_;
}

FrameResult V4l2Camera::next_frame(double timeout_s) {
  if (!streaming_) throw std::runtime_error("camera " + path_ + ": next_frame before start");
  if (lost_) return {FrameStatus::Disconnected, {}, "camera " + path_ + ": device lost"};
  const double deadline = monotonic_now_s() + timeout_s;
  for (;;) {
    const double left = deadline - monotonic_now_s();
    if (left <= 0) return {FrameStatus::Timeout, {}, "camera " + path_ + ": no frame in time"};
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, int(std::ceil(left * 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) continue;
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(fd_, VIDIOC_DQBUF, &b) != 0) {
      const int e = errno;
      if (e == EAGAIN) continue;
      lost_ = true;  // ENODEV (unplugged), EIO (device error), ...: re-open by id
      return {FrameStatus::Disconnected, {}, "camera " + path_ + ": " + errno_text(e)};
    }
    Frame frame;
    const bool ok = !(b.flags & V4L2_BUF_FLAG_ERROR) && b.index < buffers_.size() &&
                    decode(buffers_[b.index], b.bytesused, frame.image);
    const bool monotonic =
        (b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    frame.timestamp_s = monotonic && (b.timestamp.tv_sec || b.timestamp.tv_usec)
                            ? b.timestamp.tv_sec + 1e-6 * b.timestamp.tv_usec
                            : monotonic_now_s();
    frame.sequence = b.sequence;
    if (xioctl(fd_, VIDIOC_QBUF, &b) != 0 && errno == ENODEV) lost_ = true;
    if (ok) return {FrameStatus::Ok, std::move(frame), ""};
  }
}

void V4l2Camera::stop() {
  if (fd_ < 0) return;
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(fd_, VIDIOC_STREAMOFF, &type);
    streaming_ = false;
  }
  for (const Buffer& b : buffers_) munmap(b.data, b.length);
  if (!buffers_.empty()) {
    buffers_.clear();
    v4l2_requestbuffers req{};
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    xioctl(fd_, VIDIOC_REQBUFS, &req);  // count 0 frees the driver's buffers
  }
}

std::vector<DeviceInfo> list_v4l2_devices() {
  std::vector<DeviceInfo> out;
  for (int i = 0; i < 64; ++i) {
    const std::string path = "/dev/video" + std::to_string(i);
    try {
      V4l2Camera cam(path);
      out.push_back({path, cam.card(), cam.formats()});
    } catch (const std::runtime_error&) {
      // missing or not a capture node (metadata nodes of UVC cameras): not listed
    }
  }
  return out;
}

}  // namespace orthoface::capture
