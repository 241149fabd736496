#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "render/renderer.h"
#include "sim/head.h"

namespace orthoface::sim {

enum class RigKind { Ideal, Perspective };  // ideal = seed 004 orthographic, equal heights
enum class BackgroundKind { Plain, Cluttered, Photo };

// Error of one TRUE camera against its nominal pose. The angles turn the camera about the head
// origin around the camera's own axes (pitch: image x, yaw: image y, roll: view axis), so the
// origin stays on the optical axis; the offset then moves the camera (head frame, mm).
struct PoseError {
  double roll_deg = 0, yaw_deg = 0, pitch_deg = 0;
  Eigen::Vector3d offset_mm = Eigen::Vector3d::Zero();
};

struct RigOptions {
  RigKind kind = RigKind::Ideal;
  int width = 640, height = 480;                       // both images, pixels (1..8192)
  double px_per_mm = 1.6;                              // ideal rig scale
  double focal_px = 1600;                              // perspective: focal length, pixels
  double distance_mm = 1000;                           // perspective: camera centre to head origin
  PoseError front_error, side_error;                   // applied to the TRUE cameras only
  double ambient = 0.6, diffuse = 0.5;                 // render::Light
  Eigen::Vector3d light_direction{0.35, -0.45, -1.0};  // where the light travels, head frame
  double noise_sigma = 0;  // Gaussian sensor noise, grey levels (0..255 scale), per channel
  double blur_sigma = 0;   // Gaussian optical blur, pixels (applied before the noise)
  BackgroundKind background = BackgroundKind::Plain;
  cv::Scalar background_bgr{200, 200, 200};  // plain background colour
  // Photo: a photograph of a scene (any image file io/image_file.h accepts). Each camera sees
  // its own part of it, scaled to cover the frame (the side camera's part mirrored), as two
  // cameras 90 degrees apart see different walls of a room.
  std::string background_photo;
  std::uint64_t seed = 0;  // noise, cluttered background, photo crop; same seed, same images
  // Throws std::invalid_argument naming the first bad field.
  void check() const;
};

// One landmark's truth. Pixels follow capture/camera_model.h (pixel centre = index + 0.5).
struct LandmarkTruth {
  Eigen::Vector3d xyz_mm = Eigen::Vector3d::Zero();  // head frame
  Eigen::Vector2d front_px = Eigen::Vector2d::Zero(), side_px = Eigen::Vector2d::Zero();
  bool visible_front = false, visible_side = false;  // in the image, no surface in front (ray cast)
};

// What the rig produced: the photos plus everything a test needs to score a result.
struct Capture {
  cv::Mat front, side;                        // CV_8UC3 BGR photos (lighting, blur, noise)
  cv::Mat front_mask, side_mask;              // CV_8U, 255 where the head covers the pixel
  cv::Mat front_face_mask, side_face_mask;    // CV_8U face region (sim/face_mask.h); empty if
                                              // the head lacks the landmarks that bound it
  cv::Mat front_depth_mm, side_depth_mm;      // CV_32F z_cam, +inf off the head
  cv::Mat background_front, background_side;  // the empty scene, own noise draw
  capture::RigCalibration true_rig;           // the cameras that took the photos (with pose errors)
  capture::RigCalibration nominal_rig;        // what the station believes (what rig.yaml holds)
  std::map<std::string, LandmarkTruth> landmarks;  // as in head.landmarks
};

// The nominal rig for `options` (no pose errors); source "sim". Calls options.check().
capture::RigCalibration nominal_rig(const RigOptions& options);
// The true rig: nominal_rig with options.front_error / side_error applied.
capture::RigCalibration true_rig(const RigOptions& options);

// Renders `head` through the true rig and returns photos and truth. Throws
// std::invalid_argument on bad options or an empty head mesh (render::Renderer's checks).
Capture simulate_capture(const Head& head, const RigOptions& options, render::Renderer& renderer);
Capture simulate_capture(const Head& head, const RigOptions& options);  // one-off context

// The head under the rig's lighting, no noise, blur or clutter (plain background_bgr), seen by
// any `camera` (e.g. a live view's, capture::posed_camera of a moving head). Throws as
// render::Renderer::render does.
render::RenderResult render_head(const Head& head, const RigOptions& options,
                                 const capture::CameraModel& camera, render::Renderer& renderer);

// Ground truth for a new view: the head under the same lighting, no noise, blur or clutter
// (plain background_bgr), seen from yaw / pitch (radians, DESIGN.md) with the nominal front
// camera's intrinsics at the same distance. mask / depth_mm as in render::RenderResult.
render::RenderResult true_view(const Head& head, const RigOptions& options, double yaw_rad,
                               double pitch_rad, render::Renderer& renderer);

// The empty scene behind the head for one camera (0 = front, 1 = side): plain colour, a
// cluttered seeded texture, or that camera's part of the background photo, before blur and
// noise. Throws std::invalid_argument on bad options or a photo that cannot be decoded.
cv::Mat background_image(const RigOptions& options, int camera_index);

// Adds options' blur then noise to `image` (CV_8UC3); `stream` picks an independent noise draw.
cv::Mat degrade(const cv::Mat& image, const RigOptions& options, int stream);

}  // namespace orthoface::sim
