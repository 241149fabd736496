#include "capture/libcamera_camera.h"

#include <sys/mman.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <map>
#include <mutex>
#include <stdexcept>

#include <libcamera/libcamera.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file.h"

namespace orthoface::capture {
namespace {

namespace lc = libcamera;

// One CameraManager per process (a libcamera rule). Never destroyed: its threads must not be
// torn down by static destructors while a camera thread still runs.
lc::CameraManager& manager() {
  static lc::CameraManager* m = [] {
    // Quiet by default (no IPA modules here is a warning, not our error); the user's setting wins.
    setenv("LIBCAMERA_LOG_LEVELS", "*:ERROR", 0);
    auto* cm = new lc::CameraManager();
    if (cm->start() != 0) throw std::runtime_error("libcamera: CameraManager failed to start");
    return cm;
  }();
  return *m;
}

// libcamera formats we convert, and the V4L2-style name used in CameraFormat::fourcc.
// (libcamera's RGB888 is B,G,R in memory, i.e. OpenCV's BGR.)
const std::map<std::string, std::string>& names() {
  static const std::map<std::string, std::string> m = {{"RGB888", "BGR3"},
                                                       {"BGR888", "RGB3"},
                                                       {"YUYV", "YUYV"},
                                                       {"MJPEG", "MJPG"},
                                                       {"NV12", "NV12"}};
  return m;
}

double max_fps(const lc::Camera& cam) {
  const auto& info = cam.controls();
  auto it = info.find(&lc::controls::FrameDurationLimits);
  if (it == info.end()) return 30.0;
  const int64_t min_us = it->second.min().get<int64_t>();
  return min_us > 0 ? 1e6 / double(min_us) : 30.0;
}

std::vector<CameraFormat> camera_formats(lc::Camera& cam) {
  std::vector<CameraFormat> out;
  auto config = cam.generateConfiguration({lc::StreamRole::Viewfinder});
  if (!config || config->empty()) return out;
  const lc::StreamFormats& sf = config->at(0).formats();
  const double fps = max_fps(cam);
  for (const lc::PixelFormat& pf : sf.pixelformats()) {
    auto n = names().find(pf.toString());
    if (n == names().end()) continue;
    for (const lc::Size& s : sf.sizes(pf))
      out.push_back({n->second, int(s.width), int(s.height), fps});
  }
  return out;
}

class LibcameraCamera : public Camera {
 public:
  explicit LibcameraCamera(std::shared_ptr<lc::Camera> cam) : cam_(std::move(cam)) {
    if (cam_->acquire() != 0)
      throw std::runtime_error("camera libcamera:" + cam_->id() + ": in use by another process");
    cam_->disconnected.connect(this, &LibcameraCamera::on_disconnected);
  }
  ~LibcameraCamera() override {
    stop();
    cam_->disconnected.disconnect(this);
    cam_->release();
  }
  std::string name() const override { return "libcamera:" + cam_->id(); }
  std::vector<CameraFormat> formats() const override { return camera_formats(*cam_); }
  void start(const CameraFormat& format) override;
  FrameResult next_frame(double timeout_s) override;
  void stop() override;

 private:
  void on_request(lc::Request* request) {
    std::lock_guard<std::mutex> lock(m_);
    done_.push_back(request);
    cv_.notify_all();
  }
  void on_disconnected() {
    std::lock_guard<std::mutex> lock(m_);
    lost_ = true;
    cv_.notify_all();
  }
  cv::Mat convert(const lc::FrameBuffer& buffer) const;

  std::shared_ptr<lc::Camera> cam_;
  std::unique_ptr<lc::CameraConfiguration> config_;
  std::unique_ptr<lc::FrameBufferAllocator> allocator_;
  std::vector<std::unique_ptr<lc::Request>> requests_;
  std::map<const lc::FrameBuffer*, std::pair<void*, size_t>> maps_;
  lc::Stream* stream_ = nullptr;
  std::string fourcc_;
  int width_ = 0, height_ = 0, stride_ = 0;
  bool running_ = false;
  std::mutex m_;
  std::condition_variable cv_;
  std::deque<lc::Request*> done_;
  bool lost_ = false;
};

void LibcameraCamera::start(const CameraFormat& format) {
  const std::string id = name();
  if (running_) throw std::runtime_error("camera " + id + ": already started");
  std::string lc_name;
  for (const auto& [lcn, v4l2n] : names())
    if (v4l2n == format.fourcc) lc_name = lcn;
  config_ = cam_->generateConfiguration({lc::StreamRole::Viewfinder});
  if (lc_name.empty() || !config_ || config_->empty())
    throw std::runtime_error("camera " + id + ": does not offer " + format.fourcc);
  lc::StreamConfiguration& sc = config_->at(0);
  sc.pixelFormat = lc::PixelFormat::fromString(lc_name);
  sc.size = lc::Size(unsigned(format.width), unsigned(format.height));
  sc.bufferCount = 4;
  if (config_->validate() != lc::CameraConfiguration::Valid || cam_->configure(config_.get()))
    throw std::runtime_error("camera " + id + ": does not offer " + format.fourcc + " " +
                             std::to_string(format.width) + "x" + std::to_string(format.height) +
                             " (libcamera adjusted it to " + sc.toString() + ")");
  stream_ = sc.stream();
  fourcc_ = format.fourcc;
  width_ = int(sc.size.width);
  height_ = int(sc.size.height);
  stride_ = int(sc.stride);
  allocator_ = std::make_unique<lc::FrameBufferAllocator>(cam_);
  if (allocator_->allocate(stream_) < 0)
    throw std::runtime_error("camera " + id + ": cannot allocate frame buffers");
  for (const auto& buffer : allocator_->buffers(stream_)) {
    auto request = cam_->createRequest();
    if (!request || request->addBuffer(stream_, buffer.get()) != 0)
      throw std::runtime_error("camera " + id + ": cannot create a request");
    size_t length = 0;
    for (const auto& plane : buffer->planes()) length += plane.length;
    const auto& p0 = buffer->planes()[0];
    void* data = mmap(nullptr, length + p0.offset, PROT_READ, MAP_SHARED, p0.fd.get(), 0);
    if (data == MAP_FAILED) throw std::runtime_error("camera " + id + ": cannot map a buffer");
    maps_[buffer.get()] = {data, length + p0.offset};
    requests_.push_back(std::move(request));
  }
  cam_->requestCompleted.connect(this, &LibcameraCamera::on_request);
  lc::ControlList controls;
  const int64_t frame_us = int64_t(1e6 / (format.fps > 0 ? format.fps : 30.0));
  controls.set(lc::controls::FrameDurationLimits, lc::Span<const int64_t, 2>({frame_us, frame_us}));
  if (cam_->start(&controls) != 0) throw std::runtime_error("camera " + id + ": cannot start");
  running_ = true;
  for (auto& r : requests_) cam_->queueRequest(r.get());
}

cv::Mat LibcameraCamera::convert(const lc::FrameBuffer& buffer) const {
  const auto& [data, length] = maps_.at(&buffer);
  auto* base = static_cast<unsigned char*>(data) + buffer.planes()[0].offset;
  const size_t used = buffer.metadata().planes()[0].bytesused;
  cv::Mat out;
  if (fourcc_ == "BGR3") out = cv::Mat(height_, width_, CV_8UC3, base, stride_).clone();
  if (fourcc_ == "RGB3")
    cv::cvtColor(cv::Mat(height_, width_, CV_8UC3, base, stride_), out, cv::COLOR_RGB2BGR);
  if (fourcc_ == "YUYV")
    cv::cvtColor(cv::Mat(height_, width_, CV_8UC2, base, stride_), out, cv::COLOR_YUV2BGR_YUYV);
  if (fourcc_ == "NV12")  // Y plane then interleaved UV, same stride (single dmabuf)
    cv::cvtColor(cv::Mat(height_ * 3 / 2, width_, CV_8UC1, base, stride_), out,
                 cv::COLOR_YUV2BGR_NV12);
  if (fourcc_ == "MJPG")
    out = io::imdecode_accepted(cv::Mat(1, int(std::min(used, length)), CV_8U, base),
                                cv::IMREAD_COLOR);
  return out;
}

FrameResult LibcameraCamera::next_frame(double timeout_s) {
  if (!running_) throw std::runtime_error("camera " + name() + ": next_frame before start");
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait_for(lock, std::chrono::duration<double>(timeout_s),
               [this] { return lost_ || !done_.empty(); });
  if (lost_) return {FrameStatus::Disconnected, {}, "camera " + name() + ": disconnected"};
  if (done_.empty()) return {FrameStatus::Timeout, {}, "camera " + name() + ": no frame in time"};
  lc::Request* request = done_.front();
  done_.pop_front();
  lock.unlock();
  FrameResult r{FrameStatus::Timeout, {}, "camera " + name() + ": request cancelled"};
  if (request->status() == lc::Request::RequestComplete) {
    const lc::FrameBuffer* buffer = request->buffers().begin()->second;
    r.frame.image = convert(*buffer);
    r.frame.sequence = buffer->metadata().sequence;
    // FrameMetadata::timestamp: ns, CLOCK_MONOTONIC (from the V4L2 buffer, end of frame).
    const auto sensor = request->metadata().get(lc::controls::SensorTimestamp);
    const uint64_t ns =
        buffer->metadata().timestamp ? buffer->metadata().timestamp : uint64_t(sensor.value_or(0));
    r.frame.timestamp_s = ns ? double(ns) * 1e-9 : monotonic_now_s();
    if (!r.frame.image.empty()) r.status = FrameStatus::Ok, r.message.clear();
  }
  request->reuse(lc::Request::ReuseBuffers);
  cam_->queueRequest(request);
  return r;
}

void LibcameraCamera::stop() {
  if (!running_) return;
  cam_->stop();
  cam_->requestCompleted.disconnect(this);
  running_ = false;
  done_.clear();
  requests_.clear();
  for (auto& [buffer, map] : maps_) munmap(map.first, map.second);
  maps_.clear();
  allocator_->free(stream_);
  allocator_.reset();
}

}  // namespace

std::unique_ptr<Camera> open_libcamera_camera(const std::string& id) {
  lc::CameraManager& cm = manager();
  const auto cameras = cm.cameras();
  if (cameras.empty())
    throw std::runtime_error("camera libcamera:" + id + ": no libcamera cameras found");
  auto cam = cm.get(id);
  if (!cam) {
    std::string known;
    for (const auto& c : cameras) known += " libcamera:" + c->id();
    throw std::runtime_error("camera libcamera:" + id + ": unknown (found" + known + ")");
  }
  return std::make_unique<LibcameraCamera>(cam);
}

std::vector<DeviceInfo> list_libcamera_devices() {
  std::vector<DeviceInfo> out;
  for (const auto& cam : manager().cameras()) {
    const auto model = cam->properties().get(lc::properties::Model);
    out.push_back(
        {"libcamera:" + cam->id(), model.value_or("libcamera camera"), camera_formats(*cam)});
  }
  return out;
}

}  // namespace orthoface::capture
