#pragma once
// A two-camera rig given as a stereo pair (camera 1 = front, camera 2 = side, and the pose of
// camera 2 relative to camera 1), the form cv::stereoCalibrate and OpenCV's stereo_calib sample
// produce, and how our head frame (DESIGN.md: conventions) is placed on it.

#include <string>

#include <Eigen/Geometry>
#include "capture/camera_model.h"
#include "capture/rig_text.h"

namespace orthoface::capture {

// Where the optical axes of a stereo pair pass closest. The head frame placed there (the one
// `calibrate` uses): origin at the midpoint of the shortest segment between the two optical
// axes, +z = against the front camera's viewing direction (toward the front camera), +x =
// against the side camera's viewing direction made orthogonal to z (toward the side camera),
// +y = z x x (up when both cameras stand upright).
struct StereoAxes {
  Eigen::Isometry3d front_from_head = Eigen::Isometry3d::Identity();  // front camera <- head
  double gap_mm = 0;          // length of that shortest segment
  double angle_deg = 0;       // between the two viewing directions (90 for seed 004's rig)
  double front_depth_mm = 0;  // the origin's depth in front of each camera (< 0: behind it)
  double side_depth_mm = 0;
};
// `side_from_front` maps front-camera coordinates to side-camera ones (mm). Parallel axes give
// no closest point: the origin is then the front camera's centre and the frame may be NaN.
StereoAxes stereo_axes(const Eigen::Isometry3d& side_from_front);

// The rig of two cameras (intrinsics of `front` and `side`; their poses are ignored) whose
// relative pose is `side_from_front`, in the head frame of stereo_axes. Throws
// std::invalid_argument naming the problem when side_from_front is not a finite rigid motion,
// the baseline is not in (1 mm, 100 m], the axes make less than 20 deg (or more than 160), pass
// further apart than 0.1 x the baseline, or meet behind a camera, or a camera has a
// camera_problem().
RigCalibration rig_from_stereo(const CameraModel& front, const CameraModel& side,
                               const Eigen::Isometry3d& side_from_front);

// OpenCV stereo calibration file (cv::FileStorage YAML or XML, by the extension): K1 D1 K2 D2
// (3x3 camera matrices, distortion k1 k2 p1 p2 [k3]), R T (x2 = R x1 + T, T in mm), image_size
// [w, h] (image_size_2 when the side camera's differs), and orthoface_cam1_from_head (4x4), the
// head frame, which a reader without it derives with stereo_axes. Both cameras must be
// perspective. All or nothing (io/atomic_file.h); std::invalid_argument for an orthographic
// camera or a camera_problem(), std::runtime_error naming the file when it cannot be written.
void write_opencv_stereo(const RigCalibration& rig, const std::string& path);

// Reads such a file; also the names of OpenCV's stereo_calib sample (M1 M2 for K1 K2) and the
// image size as imageSize, or image_width + image_height. Distortion of 4, 5 or more
// coefficients (those past the fifth must be 0). R may be a 3x3 matrix or a Rodrigues vector.
// Without orthoface_cam1_from_head the head frame comes from rig_from_stereo. Throws
// std::runtime_error naming the file and the field that is missing, of the wrong shape,
// non-finite, absurd, not a rotation, or whose axes do not meet.
RigCalibration read_opencv_stereo(const std::string& path);
// The same from a rig file's parsed text (capture/rig_text.h); `path` names it in errors.
RigCalibration opencv_stereo_rig(const RigNode& root, const std::string& path);

}  // namespace orthoface::capture
