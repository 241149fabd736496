#pragma once
// An in-process Camera for tests, registered under "test:NAME": frames at a fixed rate with a
// chosen clock offset, optional dropped sequence numbers, and an unplug switch.
#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "capture/camera.h"

namespace orthoface::testing {

struct TestCameraConfig {
  double fps = 30;
  double offset_s = 0;  // phase of this camera's frames
  int drop_every = 0;   // > 0: every n-th sequence number is skipped (a driver drop)
  std::atomic<bool> unplugged{false};
};

inline std::map<std::string, std::shared_ptr<TestCameraConfig>>& test_cameras() {
  static std::map<std::string, std::shared_ptr<TestCameraConfig>> m;
  return m;
}

class TestCamera : public capture::Camera {
 public:
  TestCamera(std::string id, std::shared_ptr<TestCameraConfig> c) : id_(std::move(id)), c_(c) {}
  std::string name() const override { return id_; }
  std::vector<capture::CameraFormat> formats() const override {
    return {{"BGR3", 64, 48, c_->fps}, {"BGR3", 640, 480, c_->fps}};
  }
  void start(const capture::CameraFormat& f) override {
    if (f.fourcc != "BGR3" || (f.width != 64 && f.width != 640))
      throw std::runtime_error("camera " + id_ + ": format not offered");
    format_ = f;
    const double period = 1.0 / c_->fps, now = capture::monotonic_now_s();
    k_ = static_cast<std::uint64_t>(now / period) + 1;
  }
  capture::FrameResult next_frame(double timeout_s) override {
    if (c_->unplugged) return {capture::FrameStatus::Disconnected, {}, id_ + ": unplugged"};
    const double period = 1.0 / c_->fps;
    if (c_->drop_every > 0 && k_ % c_->drop_every == 0) ++k_;
    const double t = k_ * period + c_->offset_s, now = capture::monotonic_now_s();
    if (t - now > timeout_s) return {capture::FrameStatus::Timeout, {}, "timeout"};
    if (t > now) std::this_thread::sleep_for(std::chrono::duration<double>(t - now));
    capture::Frame f;
    f.image = cv::Mat(format_.height, format_.width, CV_8UC3, cv::Scalar::all(double(k_ % 256)));
    f.timestamp_s = t;
    f.sequence = k_++;
    return {capture::FrameStatus::Ok, f, ""};
  }
  void stop() override {}

 private:
  std::string id_;
  std::shared_ptr<TestCameraConfig> c_;
  capture::CameraFormat format_;
  std::uint64_t k_ = 0;
};

// Registers the "test:" backend once; returns the config of camera `name` ("test:NAME").
inline std::shared_ptr<TestCameraConfig> test_camera(const std::string& name) {
  static std::once_flag once;
  static std::mutex m;
  std::call_once(once, [] {
    capture::register_camera_backend(
        "test:", {[](const std::string& id) -> std::unique_ptr<capture::Camera> {
                    std::lock_guard<std::mutex> lock(m);
                    auto it = test_cameras().find(id);
                    if (it == test_cameras().end() || it->second->unplugged)
                      throw std::runtime_error("camera " + id + ": no such device");
                    return std::make_unique<TestCamera>(id, it->second);
                  },
                  {}});
  });
  std::lock_guard<std::mutex> lock(m);
  auto& c = test_cameras()["test:" + name];
  if (!c) c = std::make_shared<TestCameraConfig>();
  return c;
}

}  // namespace orthoface::testing
