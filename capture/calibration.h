#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/camera_model.h"

namespace orthoface::capture {

// A checkerboard: inner corners cols x rows, square side in mm (the board frame: x along cols,
// y along rows, z into the board, origin at the first inner corner).
struct Checkerboard {
  int cols = 9, rows = 6;
  double square_mm = 25;
  void check() const;  // throws std::invalid_argument naming the bad field
};

struct CalibrationOptions {
  Checkerboard board;
  int min_views = 4;                 // per camera, views showing the whole board (intrinsics)
  int min_shared_views = 2;          // views where both cameras see the board (the 90 deg pose)
  double pixel_noise = 0.5;          // assumed corner noise (px) for the pose uncertainty
  double max_translation_sd_mm = 3;  // larger predicted uncertainty on an axis: "more views"
  void check() const;
};

// Corners (pixel centres at +0.5, camera_model.h) of the board in `image` (BGR or grey),
// refined to sub-pixel, or nullopt when the whole board is not visible. Throws
// std::invalid_argument on an empty image.
std::optional<std::vector<cv::Point2f>> find_board(const cv::Mat& image, const Checkerboard& board);

struct RigCalibrationReport {
  RigCalibration rig;  // perspective models, cam_from_head as defined below
  double rms_front_px = 0, rms_side_px = 0, rms_stereo_px = 0;  // reprojection errors
  int views_front = 0, views_side = 0, views_shared = 0;
  Eigen::Isometry3d side_from_front = Eigen::Isometry3d::Identity();
  Eigen::Vector3d translation_sd_mm = Eigen::Vector3d::Zero();  // predicted, front camera axes
  std::vector<std::string> warnings;
};

// Intrinsics + distortion of each camera (cv::calibrateCamera over the views showing the board
// to that camera) and the pose between them (cv::stereoCalibrate over the views showing it to
// both, e.g. held at 45 deg). front[i] and side[i] are taken at the same moment. Head frame:
// origin where the optical axes pass closest, +z toward the front camera, +x toward the side
// camera (DESIGN.md). Throws std::invalid_argument on unequal counts or sizes, std::runtime_error
// when too few views show the board or the pose leaves a translation axis unconstrained
// (predicted sd > max_translation_sd_mm: the message says which axis and asks for more views).
RigCalibrationReport calibrate_rig(const std::vector<cv::Mat>& front,
                                   const std::vector<cv::Mat>& side,
                                   const CalibrationOptions& options = {});

// Angle (deg) of the rotation between two poses' rotations, and distance between translations.
double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

}  // namespace orthoface::capture
