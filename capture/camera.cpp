#include "capture/camera.h"

#include <time.h>

#include <algorithm>
#include <map>
#include <mutex>

#include "capture/file_camera.h"
#include "capture/v4l2_camera.h"
#ifdef ORTHOFACE_HAVE_LIBCAMERA
#include "capture/libcamera_camera.h"
#endif

namespace orthoface::capture {
namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}
std::map<std::string, CameraBackend>& registry() {
  static std::map<std::string, CameraBackend> r;
  return r;
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

int fourcc_rank(const std::string& fourcc) {
  if (fourcc == "MJPG") return 0;  // compressed: two USB cameras fit on one bus
  if (fourcc == "YUYV") return 1;
  return 2;
}

}  // namespace

void register_camera_backend(const std::string& prefix, CameraBackend backend) {
  if (prefix.empty()) throw std::invalid_argument("register_camera_backend: empty prefix");
  if (!backend.open)
    throw std::invalid_argument("register_camera_backend: no open function for '" + prefix + "'");
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[prefix] = std::move(backend);
}

std::unique_ptr<Camera> open_camera(const std::string& id) {
  if (id.empty()) throw std::runtime_error("open_camera: empty camera id");
  {
    std::lock_guard<std::mutex> lock(registry_mutex());
    for (const auto& [prefix, backend] : registry())
      if (starts_with(id, prefix)) return backend.open(id);
  }
  if (starts_with(id, "libcamera:")) {
#ifdef ORTHOFACE_HAVE_LIBCAMERA
    return open_libcamera_camera(id.substr(10));
#else
    throw std::runtime_error("camera " + id + ": this build has no libcamera support");
#endif
  }
  if (starts_with(id, "file:")) return std::make_unique<FileCamera>(id);
  if (starts_with(id, "/") || starts_with(id, ".")) return std::make_unique<V4l2Camera>(id);
  if (starts_with(id, "sim:"))
    throw std::runtime_error("camera " + id + ": the simulated rig backend is not registered");
  throw std::runtime_error(
      "camera " + id +
      ": unknown camera id (expected /dev/videoN, libcamera:ID, file:PATH or sim:N)");
}

std::unique_ptr<Camera> reopen_camera(const std::string& id, const CameraFormat& format) {
  try {
    auto cam = open_camera(id);
    cam->start(format);
    return cam;
  } catch (const std::exception&) {
    return nullptr;
  }
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> all = list_v4l2_devices();
#ifdef ORTHOFACE_HAVE_LIBCAMERA
  for (DeviceInfo& d : list_libcamera_devices()) all.push_back(std::move(d));
#endif
  std::lock_guard<std::mutex> lock(registry_mutex());
  for (const auto& [prefix, backend] : registry())
    if (backend.list)
      for (DeviceInfo& d : backend.list()) all.push_back(std::move(d));
  return all;
}

CameraFormat choose_format(const std::vector<CameraFormat>& formats, int width, int height,
                           double fps, const std::string& camera) {
  if (formats.empty()) throw std::runtime_error("camera " + camera + ": offers no usable format");
  std::vector<CameraFormat> same_size;
  for (const CameraFormat& f : formats)
    if (f.width == width && f.height == height) same_size.push_back(f);
  if (same_size.empty()) {
    std::string offered;
    for (const CameraFormat& f : formats)
      offered += " " + f.fourcc + ":" + std::to_string(f.width) + "x" + std::to_string(f.height);
    throw std::runtime_error("camera " + camera + ": no mode of " + std::to_string(width) + "x" +
                             std::to_string(height) + " (offers" + offered + ")");
  }
  auto better = [fps](const CameraFormat& a, const CameraFormat& b) {
    const bool a_fast = a.fps + 1e-6 >= fps, b_fast = b.fps + 1e-6 >= fps;
    if (a_fast != b_fast) return a_fast;
    if (fourcc_rank(a.fourcc) != fourcc_rank(b.fourcc))
      return fourcc_rank(a.fourcc) < fourcc_rank(b.fourcc);
    return a_fast ? a.fps < b.fps : a.fps > b.fps;  // the slowest mode that is fast enough
  };
  return *std::min_element(same_size.begin(), same_size.end(), better);
}

double monotonic_now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace orthoface::capture
