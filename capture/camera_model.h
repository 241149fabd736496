#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace orthoface::capture {

// How a camera maps its own 3D frame to pixels.
//   Orthographic: u = cx + fx * x_cam, v = cy + fy * y_cam   (fx, fy in pixels per mm)
//   Perspective:  OpenCV pinhole, u = cx + fx * x_cam / z_cam (+ distortion), fx, fy in pixels.
enum class Projection { Orthographic, Perspective };

// One camera placed in the head frame.
// Camera frame follows OpenCV: +x right in the image, +y down, +z forward (viewing direction).
// Head frame (DESIGN.md): origin between the ears, +x toward the side camera (the subject's
// left), +y up, +z toward the front camera (out of the face). Units: mm. Pixel origin: top-left
// corner of the top-left pixel is (0,0), so the centre of pixel (c, r) is (c + 0.5, r + 0.5).
struct CameraModel {
  Projection projection = Projection::Orthographic;
  int width = 640;  // image size, pixels
  int height = 480;
  double fx = 1.0;  // pixels per mm (orthographic) or focal length in pixels (perspective)
  double fy = 1.0;
  double cx = 320.0;  // principal point, pixels
  double cy = 240.0;
  std::vector<double> distortion;  // OpenCV k1 k2 p1 p2 [k3]; empty = none (perspective only)
  Eigen::Isometry3d cam_from_head = Eigen::Isometry3d::Identity();
};

// The two cameras of a station. In the ideal rig of seed 004 both are orthographic with equal
// scale and principal row, so a head point's row is the same in both images (seed 004 eq. 1).
struct RigCalibration {
  CameraModel front;   // looks along -z of the head frame
  CameraModel side;    // looks along -x of the head frame; the face (+z) appears on the image left
  std::string source;  // where it came from ("ideal default", file path, "sim", ...)
};

// What is wrong with a camera model, or "" when nothing is: a positive image size, finite
// fx, fy in (0, 1e6], finite cx, cy within 1e6 px, a finite pose. Every reader and user of a
// rig checks with this one rule.
std::string camera_problem(const CameraModel& camera);

// Pixel position of head-frame point p_head (mm) seen by `camera`, distortion included.
// A perspective camera returns NaN for a point at or behind its centre (z_cam <= 0).
Eigen::Vector2d project(const CameraModel& camera, const Eigen::Vector3d& p_head);

// Depth of p_head along the camera's viewing axis (z_cam, mm).
double depth(const CameraModel& camera, const Eigen::Vector3d& p_head);

// Unit viewing direction of `camera` in the head frame (where it looks).
Eigen::Vector3d view_direction(const CameraModel& camera);

// Camera that looks at the head-frame origin from yaw / pitch (radians, DESIGN.md). The yaw
// convention is physical: yaw > 0 stands at the head frame's +x, the subject's left (the face
// seems turned to its own right), whichever side a side camera stood on (report.json's
// photographed_side_yaw_sign says which sign shows the side photo's side); pitch > 0 looks from
// above. The camera stands `distance_mm` away, image up = head +y as far as the pitch allows.
// Intrinsics are copied from `intrinsics` (projection, size, fx, fy, cx, cy, distortion).
// Throws std::invalid_argument for distance_mm <= 0 with a perspective model.
CameraModel camera_at(const CameraModel& intrinsics, double yaw_rad, double pitch_rad,
                      double distance_mm);

// The camera of a new view at yaw / pitch (degrees, camera_at's convention): `rig.front`'s
// intrinsics at the front camera's distance from the head origin (at least 1 mm). Throws
// std::invalid_argument for a non-finite yaw or pitch.
CameraModel view_camera(const RigCalibration& rig, double yaw_deg, double pitch_deg);

// `camera` (any pose) seeing the head turned about `pivot` (head frame, mm): the camera moved
// around the pivot as camera_at moves a camera around the origin (yaw > 0 toward head +x, pitch
// > 0 from above; degrees), so yaw = pitch = 0 gives `camera` itself and a head turning about
// its neck stays over the body. Throws std::invalid_argument for a non-finite yaw, pitch or pivot.
CameraModel turned_camera(const CameraModel& camera, double yaw_deg, double pitch_deg,
                          const Eigen::Vector3d& pivot);

// `camera` seeing the head moved by the rigid pose X -> head_rotation * X + head_translation_mm
// (head frame, mm; e.g. a tracked head pose): cam_from_head composed with the pose, so
// project(posed_camera(c, R, t), X) == project(c, R * X + t) for every head point X; intrinsics
// unchanged. Throws std::invalid_argument on a camera_problem(), a non-finite R or t, or an R
// that is not a rotation (|R^T R - I| > 1e-6, max entry, or det R < 0).
CameraModel posed_camera(const CameraModel& camera, const Eigen::Matrix3d& head_rotation,
                         const Eigen::Vector3d& head_translation_mm);

// The camera whose image, flipped left to right, is what `camera` sees of the scene's mirror
// image through the head-frame plane n . p = d (plane = (n, d), |n| = 1): pose F cam M with M the
// reflection and F = x -> -x in the camera frame (a rotation again), cx' = width - cx and the
// tangential distortion p2 negated. Throws std::invalid_argument on a camera_problem() or a
// plane whose normal is not finite and of unit length.
CameraModel reflected(const CameraModel& camera, const Eigen::Vector4d& plane);

// The rig that took the two photos, for texturing. The model works in the head frame with the
// side camera at +x (the face on the side image's left); when that camera stood on the subject's
// right instead (vision's FaceObservation::side_faces_left == false), the model mirrored the side
// observation but not the side photo, which must be projected from where it was taken: `rig`
// with its side camera reflected through the x = 0 plane (pose, principal point and tangential
// distortion p2), i.e. standing at -x. With side_faces_left == true, `rig` unchanged. Throws
// std::invalid_argument when the side camera has a camera_problem().
RigCalibration photo_rig(const RigCalibration& rig, bool side_faces_left);

// The sign of camera_at's yaw that turns a view toward the side camera of `photo_rig` (the rig
// as the photos were taken, photo_rig()): +1 when that camera stands at +x of the head frame
// (the subject's left), -1 at -x.
double photographed_side_sign(const RigCalibration& photo_rig);

// The ideal seed 004 rig: two orthographic cameras of the given image size and scale (pixels per
// mm), head origin at the image centre. Throws std::invalid_argument on size <= 0 or scale <= 0.
RigCalibration ideal_rig(int width, int height, double px_per_mm);

// How a rig file is written: Orthoface = our own FileStorage YAML (top-level orthoface_rig,
// one section per camera with its pose in the head frame); OpenCvStereo = the file an OpenCV
// cv::stereoCalibrate workflow writes (K1 D1 K2 D2 R T, image size; capture/stereo_rig.h),
// perspective cameras only.
enum class RigFormat { Orthoface, OpenCvStereo };
// "orthoface" / "opencv"; throws std::invalid_argument naming the text otherwise.
RigFormat parse_rig_format(const std::string& name);

// OpenCV FileStorage YAML (the format `reconstruct --rig` reads and `simulate` / `calibrate`
// write). write_rig writes all or nothing (io/atomic_file.h); std::invalid_argument when
// `format` cannot hold the rig (write_opencv_stereo). read_rig reads either format (a file
// without orthoface_rig but with K1/M1 or R is read as an OpenCV stereo file) and throws
// std::runtime_error naming the file and the missing or malformed field.
void write_rig(const RigCalibration& rig, const std::string& path,
               RigFormat format = RigFormat::Orthoface);
RigCalibration read_rig(const std::string& path);

}  // namespace orthoface::capture
