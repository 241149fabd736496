#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::capture {

// One captured image. image: CV_8UC3 BGR, origin top-left. timestamp_s: when the sensor finished
// the frame, on CLOCK_MONOTONIC (seconds; V4L2 kernel timestamps and libcamera SensorTimestamp use
// this clock, so frames of two cameras are comparable). sequence: the camera's frame counter.
struct Frame {
  cv::Mat image;
  double timestamp_s = 0.0;
  std::uint64_t sequence = 0;
};

// A synchronized pair: the front and side frames whose timestamps were nearest.
struct FramePair {
  Frame front;
  Frame side;
  double skew_s = 0.0;  // |front.timestamp_s - side.timestamp_s|
};

// A mode a camera offers. fourcc: "MJPG", "YUYV", "BGR3", ... (V4L2 names).
struct CameraFormat {
  std::string fourcc;
  int width = 0;
  int height = 0;
  double fps = 0.0;
};

// Result of waiting for a frame: a frame, nothing within the timeout, or the device is gone
// (unplugged / ENODEV: the camera object is dead, re-open by id when it comes back).
enum class FrameStatus { Ok, Timeout, Disconnected };
struct FrameResult {
  FrameStatus status = FrameStatus::Timeout;
  Frame frame;          // valid when status == Ok
  std::string message;  // why, when not Ok
};

// A capture device. Single owner; not thread-safe (one thread drives it).
// Errors (device missing, not a capture device, a format it lacks, IO failure) are thrown as
// std::runtime_error naming the device; a vanished device is a FrameStatus, not an exception.
class Camera {
 public:
  virtual ~Camera() = default;
  virtual std::string name() const = 0;                   // the id it was opened with
  virtual std::vector<CameraFormat> formats() const = 0;  // modes offered
  virtual void start(const CameraFormat& format) = 0;     // throws if the mode is not offered
  virtual FrameResult next_frame(double timeout_s) = 0;   // requires start()
  virtual void stop() = 0;                                // idempotent
};

// A listed device and its modes (for `orthoface devices`).
struct DeviceInfo {
  std::string id;     // what open_camera takes: "/dev/video0", "libcamera:...", "sim:3/front"
  std::string label;  // driver / card name
  std::vector<CameraFormat> formats;
};

// Backend hooks: capture is the lowest layer, so higher layers (sim/) register their own
// backend for an id prefix ("sim:"). `open` receives the whole id; `list` may be empty.
struct CameraBackend {
  std::function<std::unique_ptr<Camera>(const std::string& id)> open;
  std::function<std::vector<DeviceInfo>()> list;
};
// Registers (or replaces) the backend for ids starting with `prefix`. Throws
// std::invalid_argument for an empty prefix or an empty open function.
void register_camera_backend(const std::string& prefix, CameraBackend backend);

// Opens "/dev/videoN" (V4L2), "libcamera:ID" or any registered prefix ("sim:N/front").
// Throws std::runtime_error naming the id when it does not exist, is not a capture device or
// its backend is not available.
std::unique_ptr<Camera> open_camera(const std::string& id);

// A camera that vanished (unplugged, its driver reset), opened again by `id` and started in
// `format`; null while it is still gone. Callers retry every kReopenIntervalS.
std::unique_ptr<Camera> reopen_camera(const std::string& id, const CameraFormat& format);
inline constexpr double kReopenIntervalS = 0.5;

// All devices of all backends (V4L2 capture nodes, libcamera cameras, registered lists).
std::vector<DeviceInfo> list_devices();

// The offered mode closest to width x height at >= fps (exact size first, MJPG preferred, then
// YUYV, then the highest fps). Throws std::runtime_error naming `camera` when nothing matches
// the size exactly, or formats is empty.
CameraFormat choose_format(const std::vector<CameraFormat>& formats, int width, int height,
                           double fps, const std::string& camera);

// Seconds on CLOCK_MONOTONIC, the clock of Frame::timestamp_s.
double monotonic_now_s();

}  // namespace orthoface::capture
