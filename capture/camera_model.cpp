#include "capture/camera_model.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>
#include <stdexcept>

#include <opencv2/core/eigen.hpp>

#include "capture/rig_text.h"
#include "capture/stereo_rig.h"

namespace orthoface::capture {
namespace {

Eigen::Vector2d distort(const std::vector<double>& d, const Eigen::Vector2d& xy) {
  if (d.empty()) return xy;
  const double k1 = d.size() > 0 ? d[0] : 0, k2 = d.size() > 1 ? d[1] : 0;
  const double p1 = d.size() > 2 ? d[2] : 0, p2 = d.size() > 3 ? d[3] : 0;
  const double k3 = d.size() > 4 ? d[4] : 0;
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
          y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

const char* projection_name(Projection p) {
  return p == Projection::Orthographic ? "orthographic" : "perspective";
}

void write_camera(cv::FileStorage& fs, const std::string& key, const CameraModel& c) {
  fs << key << "{";
  fs << "projection" << projection_name(c.projection);
  fs << "width" << c.width << "height" << c.height;
  cv::Mat k = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  fs << "camera_matrix" << k;
  fs << "distortion"
     << cv::Mat(c.distortion.empty() ? std::vector<double>(5, 0.0) : c.distortion, true)
            .reshape(1, 1);
  cv::Mat pose;
  cv::eigen2cv(Eigen::Matrix4d(c.cam_from_head.matrix()), pose);
  fs << "cam_from_head" << pose;
  fs << "}";
}

using Fail = std::function<void(const std::string&)>;

// Matrix field `name` of camera section `n` as CV_64F; empty when the field is absent (the
// caller says it is missing).
cv::Mat read_matrix(const RigNode& n, const std::string& name, const Fail& fail) {
  const RigNode* m = n.find(name);
  if (!m) return {};
  try {
    return matrix_from_node(*m);
  } catch (const std::invalid_argument& e) {
    fail(name + " " + e.what());
  }
  return {};
}

CameraModel read_camera(const RigNode& root, const std::string& key, const std::string& path) {
  const Fail fail = [&](const std::string& what) {
    throw std::runtime_error("rig file " + path + ": " + key + ": " + what);
  };
  const RigNode* n = root.find(key);
  if (!n || !n->is_map()) fail("missing camera section");
  CameraModel c;
  const RigNode* projection = n->find("projection");
  const std::string proj = projection && projection->is_scalar() ? projection->text : "";
  if (proj == "orthographic")
    c.projection = Projection::Orthographic;
  else if (proj == "perspective")
    c.projection = Projection::Perspective;
  else
    fail("projection must be orthographic or perspective, got '" + proj + "'");
  const RigNode *width = n->find("width"), *height = n->find("height");
  if (!width || !height) fail("missing width/height");
  const std::optional<long long> w = width->as_int(), h = height->as_int();
  if (!w || !h) fail("image size: width and height must be whole numbers of pixels");
  if (*w <= 0 || *h <= 0 || *w > 20000 || *h > 20000)
    fail("image size " + std::to_string(*w) + "x" + std::to_string(*h) + " out of range");
  c.width = int(*w);
  c.height = int(*h);
  const cv::Mat k = read_matrix(*n, "camera_matrix", fail);
  if (k.rows != 3 || k.cols != 3) fail("camera_matrix must be 3x3");
  c.fx = k.at<double>(0, 0);
  c.fy = k.at<double>(1, 1);
  c.cx = k.at<double>(0, 2);
  c.cy = k.at<double>(1, 2);
  if (const std::string why = camera_problem(c); !why.empty()) fail("camera_matrix: " + why);
  const cv::Mat d = read_matrix(*n, "distortion", fail);
  if (!d.empty()) {
    if (d.total() != 4 && d.total() != 5) fail("distortion must have 4 or 5 coefficients");
    c.distortion.assign(d.begin<double>(), d.end<double>());
    bool all_zero = true;
    for (double v : c.distortion) {
      if (!std::isfinite(v)) fail("distortion has a non-finite coefficient");
      all_zero = all_zero && v == 0.0;
    }
    if (all_zero) c.distortion.clear();
  }
  const cv::Mat pose = read_matrix(*n, "cam_from_head", fail);
  if (pose.rows != 4 || pose.cols != 4) fail("cam_from_head must be a 4x4 matrix");
  Eigen::Matrix4d m;
  cv::cv2eigen(pose, m);
  if (!m.allFinite()) fail("cam_from_head has non-finite entries");
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-4 || r.determinant() < 0)
    fail("cam_from_head rotation is not a proper rotation");
  c.cam_from_head.matrix() = m;
  return c;
}

}  // namespace

Eigen::Vector2d project(const CameraModel& camera, const Eigen::Vector3d& p_head) {
  const Eigen::Vector3d p = camera.cam_from_head * p_head;
  if (camera.projection == Projection::Orthographic)
    return {camera.cx + camera.fx * p.x(), camera.cy + camera.fy * p.y()};
  // A point at or behind the camera centre has no image: NaN, so callers can test it.
  if (!(p.z() > 0)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Eigen::Vector2d xy = distort(camera.distortion, p.head<2>() / p.z());
  return {camera.cx + camera.fx * xy.x(), camera.cy + camera.fy * xy.y()};
}

double depth(const CameraModel& camera, const Eigen::Vector3d& p_head) {
  return (camera.cam_from_head * p_head).z();
}

Eigen::Vector3d view_direction(const CameraModel& camera) {
  return camera.cam_from_head.linear().transpose() * Eigen::Vector3d::UnitZ();
}

CameraModel camera_at(const CameraModel& intrinsics, double yaw_rad, double pitch_rad,
                      double distance_mm) {
  if (intrinsics.projection == Projection::Perspective && !(distance_mm > 0))
    throw std::invalid_argument("camera_at: perspective camera needs distance_mm > 0, got " +
                                std::to_string(distance_mm));
  if (!std::isfinite(yaw_rad) || !std::isfinite(pitch_rad))
    throw std::invalid_argument("camera_at: yaw and pitch must be finite");
  CameraModel c = intrinsics;
  // Camera centre direction in the head frame; yaw 0 = +z (front), yaw 90 deg = +x (side).
  const Eigen::Vector3d dir(std::sin(yaw_rad) * std::cos(pitch_rad), std::sin(pitch_rad),
                            std::cos(yaw_rad) * std::cos(pitch_rad));
  const Eigen::Vector3d forward = -dir;  // camera +z in head frame
  // Image "down" is head -y projected onto the image plane; "right" completes the frame. At
  // pitch = +-90 deg this uses the yaw direction so the frame stays defined.
  Eigen::Vector3d right(std::cos(yaw_rad), 0.0, -std::sin(yaw_rad));
  const Eigen::Vector3d down = forward.cross(right).normalized();
  right = down.cross(forward).normalized();
  Eigen::Matrix3d head_from_cam_r;
  head_from_cam_r.col(0) = right;
  head_from_cam_r.col(1) = down;
  head_from_cam_r.col(2) = forward;
  const double d = distance_mm > 0 ? distance_mm : 1000.0;  // orthographic: any distance works
  Eigen::Isometry3d head_from_cam = Eigen::Isometry3d::Identity();
  head_from_cam.linear() = head_from_cam_r;
  head_from_cam.translation() = dir * d;
  c.cam_from_head = head_from_cam.inverse();
  return c;
}

std::string camera_problem(const CameraModel& c) {
  constexpr double kMaxFocal = 1e6, kMaxCentre = 1e6;
  if (c.width <= 0 || c.height <= 0)
    return "image size " + std::to_string(c.width) + "x" + std::to_string(c.height) +
           " is not positive";
  if (!(c.fx > 0 && c.fx <= kMaxFocal) || !(c.fy > 0 && c.fy <= kMaxFocal))
    return "fx, fy must be finite, positive and at most 1e6";
  if (!(std::abs(c.cx) <= kMaxCentre) || !(std::abs(c.cy) <= kMaxCentre))
    return "cx, cy must be finite and within 1e6 px";
  if (!c.cam_from_head.matrix().allFinite()) return "the pose has non-finite entries";
  return "";
}

CameraModel view_camera(const RigCalibration& rig, double yaw_deg, double pitch_deg) {
  const double distance = std::max(rig.front.cam_from_head.translation().norm(), 1.0);
  return camera_at(rig.front, yaw_deg * M_PI / 180, pitch_deg * M_PI / 180, distance);
}

CameraModel turned_camera(const CameraModel& camera, double yaw_deg, double pitch_deg,
                          const Eigen::Vector3d& pivot) {
  if (!std::isfinite(yaw_deg) || !std::isfinite(pitch_deg) || !pivot.allFinite())
    throw std::invalid_argument("turned camera: yaw, pitch and pivot must be finite");
  // camera_at's turn as a rotation of the head frame: its camera axes at (yaw, pitch) are those
  // at (0, 0) rotated by r.
  const Eigen::Matrix3d at0 = camera_at(camera, 0, 0, 1).cam_from_head.linear().transpose();
  const Eigen::Matrix3d at = camera_at(camera, yaw_deg * M_PI / 180, pitch_deg * M_PI / 180, 1)
                                 .cam_from_head.linear()
                                 .transpose();
  const Eigen::Matrix3d r = at * at0.transpose();
  // head_from_cam' = T(pivot) r T(-pivot) head_from_cam.
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = r;
  turn.translation() = pivot - r * pivot;
  CameraModel c = camera;
  c.cam_from_head = (turn * camera.cam_from_head.inverse()).inverse();
  return c;
}

CameraModel posed_camera(const CameraModel& camera, const Eigen::Matrix3d& head_rotation,
                         const Eigen::Vector3d& head_translation_mm) {
  if (const std::string why = camera_problem(camera); !why.empty())
    throw std::invalid_argument("posed camera: " + why);
  if (!head_rotation.allFinite() || !head_translation_mm.allFinite())
    throw std::invalid_argument("posed camera: the head rotation and translation must be finite");
  const double off_orthogonal =
      (head_rotation.transpose() * head_rotation - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  if (off_orthogonal > 1e-6 || head_rotation.determinant() < 0)
    throw std::invalid_argument(
        "posed camera: the head rotation is not a rotation (R^T R differs from I by " +
        std::to_string(off_orthogonal) + ", det " + std::to_string(head_rotation.determinant()) +
        ")");
  // cam_from_head' X = cam_from_head (R X + t).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = head_rotation;
  pose.translation() = head_translation_mm;
  CameraModel c = camera;
  c.cam_from_head = camera.cam_from_head * pose;
  return c;
}

CameraModel reflected(const CameraModel& camera, const Eigen::Vector4d& plane) {
  if (const std::string why = camera_problem(camera); !why.empty())
    throw std::invalid_argument("reflected camera: " + why);
  const Eigen::Vector3d n = plane.head<3>();
  if (!plane.allFinite() || std::abs(n.norm() - 1) > 1e-6)
    throw std::invalid_argument("reflected camera: the plane's normal must be finite and unit");
  // cam' = F cam(M p) with M p = A p + b the reflection; u' = width - u(M p) needs cx' = width -
  // cx.
  const Eigen::Matrix3d a = Eigen::Matrix3d::Identity() - 2 * n * n.transpose();
  const Eigen::Vector3d b = 2 * plane.w() * n;
  const Eigen::Matrix3d flip = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  CameraModel c = camera;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = flip * camera.cam_from_head.linear() * a;
  pose.translation() =
      flip * (camera.cam_from_head.linear() * b + camera.cam_from_head.translation());
  c.cam_from_head = pose;
  c.cx = c.width - camera.cx;
  if (c.distortion.size() >= 4) c.distortion[3] = -c.distortion[3];
  return c;
}

RigCalibration photo_rig(const RigCalibration& rig, bool side_faces_left) {
  if (side_faces_left) return rig;
  if (const std::string why = camera_problem(rig.side); !why.empty())
    throw std::invalid_argument("photo rig: side camera: " + why);
  RigCalibration out = rig;
  out.side = reflected(rig.side, Eigen::Vector4d(1, 0, 0, 0));  // through x = 0
  return out;
}

double photographed_side_sign(const RigCalibration& photo_rig) {
  return photo_rig.side.cam_from_head.inverse().translation().x() >= 0 ? 1.0 : -1.0;
}

RigCalibration ideal_rig(int width, int height, double px_per_mm) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("ideal_rig: image size must be positive, got " +
                                std::to_string(width) + "x" + std::to_string(height));
  if (!(px_per_mm > 0)) throw std::invalid_argument("ideal_rig: px_per_mm must be positive");
  CameraModel base;
  base.projection = Projection::Orthographic;
  base.width = width;
  base.height = height;
  base.fx = base.fy = px_per_mm;
  base.cx = width / 2.0;
  base.cy = height / 2.0;
  RigCalibration rig;
  rig.front = camera_at(base, 0.0, 0.0, 1000.0);
  rig.side = camera_at(base, M_PI / 2, 0.0, 1000.0);
  rig.source = "ideal";
  return rig;
}

RigFormat parse_rig_format(const std::string& name) {
  if (name == "orthoface") return RigFormat::Orthoface;
  if (name == "opencv") return RigFormat::OpenCvStereo;
  throw std::invalid_argument("rig format must be orthoface or opencv, got '" + name + "'");
}

void write_rig(const RigCalibration& rig, const std::string& path, RigFormat format) {
  if (format == RigFormat::OpenCvStereo) return write_opencv_stereo(rig, path);
  // Checked here so OpenCV does not log its own error line before we throw.
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw std::runtime_error("cannot write rig file " + path + ": folder " + parent.string() +
                             " does not exist");
  write_rig_text(path, [&](cv::FileStorage& fs) {
    fs << "orthoface_rig" << 1;
    fs << "source" << rig.source;
    write_camera(fs, "front", rig.front);
    write_camera(fs, "side", rig.side);
  });
}

RigCalibration read_rig(const std::string& path) {
  const RigNode root = read_rig_text(path);
  if (!root.find("orthoface_rig")) {
    if (root.find("K1") || root.find("M1") || root.find("R")) return opencv_stereo_rig(root, path);
    throw std::runtime_error("rig file " + path +
                             ": missing 'orthoface_rig' version key (and not an OpenCV stereo "
                             "calibration with K1 D1 K2 D2 R T)");
  }
  RigCalibration rig;
  rig.front = read_camera(root, "front", path);
  rig.side = read_camera(root, "side", path);
  if (const RigNode* source = root.find("source"); source && source->is_scalar())
    rig.source = source->text;
  if (rig.source.empty()) rig.source = path;
  return rig;
}

}  // namespace orthoface::capture
