#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>

#include "capture/camera.h"
#include "capture/camera_model.h"

namespace orthoface::sim {

// What a simulated station camera shows: subject `subject` (make_head seed) on the ideal rig,
// moving its head over a loop of cycle_frames frames. Frame k (the frame's sequence number,
// looping: k mod cycle_frames, N = cycle_frames) shows the head at
//   yaw   = motion_deg * sin(2 pi k / N)   (turning; > 0 turns the nose toward head +x)
//   pitch = pitch_deg  * sin(4 pi k / N)   (nodding twice per turn; > 0 lifts the nose, head +y)
// about the head origin; sim_head_rotation / sim_camera_rig give the truth of each frame.
// With `turn` the head instead turns once, from frontal to motion_deg (-90 = a full profile
// showing the side the side camera sees, up to 45 the other way), without nodding:
//   yaw   = motion_deg * k / (N - 1)   (k = 0 .. N-1, then again from frontal)
// the one-camera enrolment's subject looking at the camera, then turning; front camera only.
// With mouth_mm > 0 the subject talks: its mouth opens and closes kMouthCycles times a loop,
//   open  = mouth_mm * (1 - cos(2 pi kMouthCycles k / N)) / 2   (sim::open_mouth: the chin
//   lowered by `open` mm), frame k = 0 closed.
inline constexpr int kMouthCycles = 3;
struct SimCameraOptions {
  int subject = 0;
  bool side = false;         // false: front camera, true: side camera
  int cycle_frames = 12;     // distinct poses rendered at start (then repeated), 1..240
  double motion_deg = 3;     // head yaw amplitude of the loop, |.| <= 30 (-90..45 with turn)
  bool turn = false;         // one turn from frontal to motion_deg instead of the sine loop
  double pitch_deg = 0;      // head pitch (nod) amplitude of the loop, |.| <= 20
  double noise_sigma = 0;    // Gaussian sensor noise (RigOptions::noise_sigma), 0..20, a new
                             // draw in every frame of the loop
  double phase_s = -1;       // frame clock offset; < 0: 0 for front, 7 ms for side
  double jitter_s = 0.0005;  // uniform timestamp jitter (+-), like a USB camera's
  double mouth_mm = 0;       // how far the talking mouth opens (chin lowered, mm), 0..15
  // Throws std::invalid_argument naming the first bad field.
  void check() const;
};

// The cameras that took frame `sequence` at width x height (the modes' sizes): sim::true_rig of
// the RigOptions the frame was rendered with, i.e. the ideal rig scaled with the width
// (RigOptions::px_per_mm * width / 640) and the head's turn played as the cameras turning about
// the head origin (sim::PoseError): front yaw_deg = yaw, pitch_deg = pitch; side yaw_deg = yaw,
// roll_deg = -pitch (the side camera looks along -x, its image x is -z, so the head's pitch is
// a roll of that camera by -pitch). Project sim::make_head(subject) points through it to find
// them in the frame whose capture::Frame::sequence is `sequence` (with mouth_mm, the points below
// the lips where sim::open_mouth(head, sim_mouth_open_mm(...)) moves them). In a turn past -45
// degrees the front camera is the side camera's model (which draws that frame: the head turned by
// -90 seen from the side, turned by the rest). Throws std::invalid_argument on bad options or size.
capture::RigCalibration sim_camera_rig(const SimCameraOptions& options, int width, int height,
                                       std::uint64_t sequence);

// The head's rotation P in frame `sequence` (head frame, about its origin): the true cameras of
// sim_camera_rig are the nominal ones composed with P, R_true = R_nominal * P for both cameras
// (R = cam_from_head.linear(), translation unchanged), so P = R_nominal^T * R_true and a head
// point p is seen where the nominal rig would see P * p. P = Rx(-pitch) * Ry(yaw) with the angles
// of SimCameraOptions: yaw > 0 turns the nose toward head +x, pitch > 0 lifts it (toward +y).
// Throws std::invalid_argument on bad options.
Eigen::Matrix3d sim_head_rotation(const SimCameraOptions& options, std::uint64_t sequence);

// How far the mouth is open in frame `sequence` (mm the chin is lowered; 0 without mouth_mm).
// Throws std::invalid_argument on bad options.
double sim_mouth_open_mm(const SimCameraOptions& options, std::uint64_t sequence);

// A capture::Camera backed by the simulated rig: modes BGR3 320x240 / 640x480 / 1280x720 at 30
// or 15 fps; frames arrive at the mode's rate with CLOCK_MONOTONIC timestamps. The poses are
// rendered (OSMesa) in start(), so next_frame costs a copy.
std::unique_ptr<capture::Camera> open_sim_camera(const SimCameraOptions& options);

// Parses "sim:N/front" or "sim:N/side" (N >= 0) and opens it; the camera's name is the id. An
// optional query sets the motion: "sim:N/front?yaw=25&pitch=15&frames=60&noise=2&mouth=8" (yaw
// -> motion_deg, pitch -> pitch_deg, frames -> cycle_frames, noise -> noise_sigma, mouth ->
// mouth_mm; the rest keep their defaults); "turn=DEG" instead of yaw plays one turn to DEG (turn =
// true, motion_deg = DEG): "sim:N/front?turn=-90&frames=46" (not with pitch or on a side camera).
// Throws std::runtime_error naming the id (and the key) when it does not match, a key is unknown, a
// value is not a number or is out of range.
std::unique_ptr<capture::Camera> open_sim_camera(const std::string& id);

// Registers the "sim:" backend with capture::open_camera / list_devices (idempotent).
void register_sim_cameras();

}  // namespace orthoface::sim
