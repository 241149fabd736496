#pragma once

// Internal to render/: colour equalisation of the two source photos for ViewSynthesizer.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "render/new_view.h"

namespace orthoface::render::detail {

// Where `camera` sees head point p: the pixel without distortion (the depth maps' projection).
Eigen::Vector2d undistorted_pixel(const capture::CameraModel& camera, const Eigen::Vector3d& p);

// Cosine between unit normal n at p and the direction from p toward `camera`.
double facing(const capture::CameraModel& camera, const Eigen::Vector3d& p,
              const Eigen::Vector3d& n);

// True when source `camera` with z_cam depth map `depth` (CV_32F, +inf empty) sees p, whose
// facing cosine is `cosine` (> 0 needed); tolerance as in the synthesis shader.
bool source_sees(const capture::CameraModel& camera, const cv::Mat& depth, const Eigen::Vector3d& p,
                 double cosine, double tolerance_mm);

// Bilinear BGR sample at pixel position uv (pixel-centre convention of camera_model.h).
cv::Vec3d bilinear(const cv::Mat& bgr, const Eigen::Vector2d& uv);

// Lab statistics of both photos over vertices both cameras see well, and the fill colour (mean
// of the front photo over the surface it sees, after equalisation).
ColourMatch colour_match(const std::vector<Eigen::Vector3d>& vertices,
                         const std::vector<Eigen::Vector3d>& normals,
                         const capture::RigCalibration& rig, const std::array<cv::Mat, 2>& depth,
                         const std::array<cv::Mat, 2>& photos);

// `photo` (8-bit BGR) of `source` (0 front, 1 side) mapped to the front photo's Lab statistics
// in `match` (the front photo itself is returned as it is); a copy of the photo when match.samples
// < kMinSamples.
constexpr int kMinSamples = 20;
cv::Mat equalized(const cv::Mat& photo, const ColourMatch& match, int source);

// The same mapping sampled on an n x n x n grid of colours, for a 3D lookup texture: a 1 x n^3
// CV_32FC3 of BGR (0..1) whose entry (b * n + g) * n + r is the mapping of the colour
// (b, g, r) / (n - 1); the identity when match.samples < kMinSamples. Throws
// std::invalid_argument when n is outside 2..256.
cv::Mat equalize_grid(const ColourMatch& match, int source, int n);

}  // namespace orthoface::render::detail
