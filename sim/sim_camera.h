#pragma once

#include <memory>
#include <string>

#include "capture/camera.h"

namespace orthoface::sim {

// What a simulated station camera shows: subject `subject` (make_head seed) on the ideal rig,
// turning its head by +-motion_deg over a loop of cycle_frames frames.
struct SimCameraOptions {
  int subject = 0;
  bool side = false;         // false: front camera, true: side camera
  int cycle_frames = 12;     // distinct poses rendered at start (then repeated)
  double motion_deg = 3;     // head yaw amplitude of the loop
  double phase_s = -1;       // frame clock offset; < 0: 0 for front, 7 ms for side
  double jitter_s = 0.0005;  // uniform timestamp jitter (+-), like a USB camera's
  // Throws std::invalid_argument naming the first bad field.
  void check() const;
};

// A capture::Camera backed by the simulated rig: modes BGR3 320x240 / 640x480 / 1280x720 at 30
// or 15 fps; frames arrive at the mode's rate with CLOCK_MONOTONIC timestamps. The poses are
// rendered (OSMesa) in start(), so next_frame costs a copy.
std::unique_ptr<capture::Camera> open_sim_camera(const SimCameraOptions& options);

// Parses "sim:N/front" or "sim:N/side" (N >= 0) and opens it. Throws std::runtime_error naming
// the id when it does not match.
std::unique_ptr<capture::Camera> open_sim_camera(const std::string& id);

// Registers the "sim:" backend with capture::open_camera / list_devices (idempotent).
void register_sim_cameras();

}  // namespace orthoface::sim
