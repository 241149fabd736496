#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/camera.h"

namespace orthoface::capture {

struct PairCaptureOptions {
  int width = 640, height = 480;  // mode asked of both cameras (choose_format)
  double fps = 30;
  std::string fourcc;                           // "" = best offered (MJPG, then YUYV)
  double max_skew_s = 0.025;                    // frames further apart than this never pair
  double reopen_interval_s = kReopenIntervalS;  // retry period for a camera that vanished
  int keep_recent = 8;                          // frames / pairs kept for pairing and live view
  // Throws std::invalid_argument naming the first bad field.
  void check() const;
};

// Counters of a run (since start); fps over the last second of frames.
struct PairStats {
  double fps_front = 0, fps_side = 0, fps_pairs = 0;
  std::uint64_t frames_front = 0, frames_side = 0, pairs = 0;
  std::uint64_t dropped_front = 0, dropped_side = 0;  // sequence gaps (lost before us)
  std::uint64_t unpaired = 0;                         // frames with no partner within max_skew
  double skew_last_s = 0, skew_mean_s = 0, skew_max_s = 0;
  bool front_connected = false, side_connected = false;
  int disconnects = 0, reconnects = 0;
};

// Two cameras, each read on its own thread; frames are paired with their nearest partner in
// time (mutual nearest timestamps, |skew| <= max_skew_s). A camera that disappears is reported
// (events(), stats) and re-opened by id every reopen_interval_s until it is back; pairs already
// taken are kept (taken()).
class PairCapture {
 public:
  // Opens and starts both cameras (open_camera). Throws std::invalid_argument when both ids
  // name the same device or options are bad, std::runtime_error naming the device otherwise.
  PairCapture(const std::string& front_id, const std::string& side_id,
              const PairCaptureOptions& options = {});
  ~PairCapture();  // stops both threads
  PairCapture(const PairCapture&) = delete;
  PairCapture& operator=(const PairCapture&) = delete;

  // The newest pair formed so far (for live views), or nullopt before the first.
  std::optional<FramePair> latest_pair() const;
  // The newest frame of each camera, whatever its partner (lowest latency live view).
  std::optional<Frame> latest_front() const;
  std::optional<Frame> latest_side() const;
  // Waits up to timeout_s for a pair whose frames both end after this call, records it in
  // taken() and returns it; nullopt on timeout (e.g. a camera is gone).
  std::optional<FramePair> take_pair(double timeout_s);
  std::vector<FramePair> taken() const;
  PairStats stats() const;
  // Messages since the last call ("front /dev/video0 lost: ...", "... back"), oldest first.
  std::vector<std::string> events();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Pairs two time-sorted frame sequences by mutual nearest timestamps within max_skew_s (the
// rule PairCapture applies online). Frames left without a partner are skipped. Throws
// std::invalid_argument when max_skew_s <= 0.
std::vector<FramePair> pair_frames(const std::vector<Frame>& front, const std::vector<Frame>& side,
                                   double max_skew_s);

// True when a and b name the same device ("/dev/video0" and "/dev/./video0", symlinks).
bool same_device(const std::string& a, const std::string& b);

}  // namespace orthoface::capture
