#include "capture/stereo_rig.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "capture/rig_text.h"

namespace orthoface::capture {
namespace {

constexpr double kMinAxesAngleDeg = 20;  // nearly parallel axes leave the x axis undefined
constexpr double kMaxGapPerBaseline = 0.1;
constexpr double kMaxBaselineMm = 1e5;
constexpr double kRotationTol = 1e-5;  // |R^T R - I| and |det R - 1| (float files pass)

bool is_rotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < kRotationTol &&
         std::abs(r.determinant() - 1) < kRotationTol;
}

using Fail = std::function<void(const std::string& field, const std::string& what)>;

// `name` (or its alternative `alt`, e.g. the stereo_calib sample's M1 for K1) as a CV_64F
// matrix; fails when missing, not a matrix or not finite.
cv::Mat read_mat(const RigNode& root, const std::string& name, const std::string& alt,
                 const Fail& fail) {
  std::string key = name;
  if (!root.find(key) && !alt.empty() && root.find(alt)) key = alt;
  const RigNode* n = root.find(key);
  if (!n) fail(alt.empty() ? name : name + " (or " + alt + ")", "missing");
  cv::Mat m;
  try {
    m = matrix_from_node(*n);
  } catch (const std::invalid_argument& e) {
    fail(key, e.what());
  }
  if (!cv::checkRange(m)) fail(key, "has a non-finite value");
  return m;
}

// Camera intrinsics from K (3x3, no skew) and D (4, 5 or more coefficients, past the fifth 0).
CameraModel read_camera(const RigNode& fs, int index, const Fail& fail) {
  const std::string k_name = "K" + std::to_string(index), d_name = "D" + std::to_string(index);
  const cv::Mat k = read_mat(fs, k_name, "M" + std::to_string(index), fail);
  if (k.rows != 3 || k.cols != 3)
    fail(k_name, "must be 3x3, got " + std::to_string(k.rows) + "x" + std::to_string(k.cols));
  const double scale = std::abs(k.at<double>(0, 0)) + std::abs(k.at<double>(1, 1));
  if (std::abs(k.at<double>(0, 1)) > 1e-9 * scale || k.at<double>(1, 0) != 0 ||
      k.at<double>(2, 0) != 0 || k.at<double>(2, 1) != 0 || k.at<double>(2, 2) != 1)
    fail(k_name, "must be [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  CameraModel c;
  c.projection = Projection::Perspective;
  c.fx = k.at<double>(0, 0), c.fy = k.at<double>(1, 1);
  c.cx = k.at<double>(0, 2), c.cy = k.at<double>(1, 2);
  const cv::Mat d = read_mat(fs, d_name, "", fail);
  if (d.rows != 1 && d.cols != 1) fail(d_name, "must be a row or column vector");
  const std::vector<double> dv(d.begin<double>(), d.end<double>());
  if (dv.size() < 4)
    fail(d_name, "must hold 4 or more coefficients (k1 k2 p1 p2 [k3 ...]), got " +
                     std::to_string(dv.size()));
  for (size_t i = 5; i < dv.size(); ++i)
    if (dv[i] != 0)
      fail(d_name, "coefficient " + std::to_string(i + 1) +
                       " is not 0: only k1 k2 p1 p2 k3 are supported (no rational, thin-prism or "
                       "tilt terms)");
  c.distortion.assign(dv.begin(), dv.begin() + std::min<size_t>(dv.size(), 5));
  if (std::all_of(c.distortion.begin(), c.distortion.end(), [](double v) { return v == 0; }))
    c.distortion.clear();  // as our own reader: no distortion is an empty list
  return c;
}

// The image size: `size_key` / `alt_key` as [w, h], or `width_key` + `height_key`.
bool read_size(const RigNode& root, const std::vector<std::string>& size_keys,
               const std::string& width_key, const std::string& height_key, int& w, int& h,
               const Fail& fail) {
  for (const std::string& key : size_keys) {
    const RigNode* n = root.find(key);
    if (!n) continue;
    if (!n->is_seq() || n->items.size() != 2 || !n->items[0].as_int() || !n->items[1].as_int())
      fail(key, "must be [width, height] in whole pixels");
    w = int(*n->items[0].as_int()), h = int(*n->items[1].as_int());
    return true;
  }
  const RigNode *width = root.find(width_key), *height = root.find(height_key);
  if (!width && !height) return false;
  if (!width || !height || !width->as_int() || !height->as_int())
    fail(width_key + " / " + height_key, "must both be whole numbers of pixels");
  w = int(*width->as_int()), h = int(*height->as_int());
  return true;
}

Eigen::Isometry3d read_pose(const RigNode& fs, const Fail& fail) {
  cv::Mat r = read_mat(fs, "R", "", fail);
  if (r.total() == 3) {
    cv::Mat rm;
    cv::Rodrigues(r.reshape(1, 3), rm);
    r = rm;
  }
  if (r.rows != 3 || r.cols != 3) fail("R", "must be a 3x3 rotation matrix or a Rodrigues vector");
  Eigen::Matrix3d R;
  cv::cv2eigen(r, R);
  if (!is_rotation(R)) fail("R", "is not a rotation (R^T R = I, det R = +1)");
  const cv::Mat t = read_mat(fs, "T", "", fail);
  if (t.total() != 3) fail("T", "must hold 3 values (mm)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = R;
  pose.translation() = Eigen::Vector3d(t.at<double>(0), t.at<double>(1), t.at<double>(2));
  return pose;
}

}  // namespace

StereoAxes stereo_axes(const Eigen::Isometry3d& side_from_front) {
  const Eigen::Isometry3d front_from_side = side_from_front.inverse();
  const Eigen::Vector3d c1 = Eigen::Vector3d::Zero(), d1 = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d c2 = front_from_side.translation();
  const Eigen::Vector3d d2 = front_from_side.linear() * Eigen::Vector3d::UnitZ();
  const double b = d1.dot(d2), denom = 1 - b * b;
  const Eigen::Vector3d w = c1 - c2;
  StereoAxes a;
  a.front_depth_mm = denom > 1e-9 ? (b * d2.dot(w) - d1.dot(w)) / denom : 0.0;
  a.side_depth_mm = denom > 1e-9 ? (d2.dot(w) - b * d1.dot(w)) / denom : 0.0;
  const Eigen::Vector3d p1 = c1 + a.front_depth_mm * d1, p2 = c2 + a.side_depth_mm * d2;
  a.gap_mm = (p1 - p2).norm();
  a.angle_deg = std::acos(std::clamp(b, -1.0, 1.0)) * 180 / M_PI;
  const Eigen::Vector3d z = -d1;
  const Eigen::Vector3d x = (-d2 - (-d2).dot(z) * z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  a.front_from_head.linear().col(0) = x;  // columns: head axes in front camera coordinates
  a.front_from_head.linear().col(1) = y;
  a.front_from_head.linear().col(2) = z;
  a.front_from_head.translation() = 0.5 * (p1 + p2);
  return a;
}

RigCalibration rig_from_stereo(const CameraModel& front, const CameraModel& side,
                               const Eigen::Isometry3d& side_from_front) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("stereo rig: " + what);
  };
  if (!is_rotation(side_from_front.linear()) || !side_from_front.translation().allFinite())
    fail("R, T is not a finite rotation and translation");
  const double baseline = side_from_front.translation().norm();
  if (!(baseline > 1 && baseline <= kMaxBaselineMm))
    fail("T: the baseline " + std::to_string(baseline) + " mm is not in (1 mm, 100 m]");
  const StereoAxes a = stereo_axes(side_from_front);
  if (a.angle_deg < kMinAxesAngleDeg || a.angle_deg > 180 - kMinAxesAngleDeg)
    fail("R: the optical axes make " + std::to_string(a.angle_deg) +
         " deg; the side camera must look across the front camera's axis (about 90 deg)");
  if (a.gap_mm > kMaxGapPerBaseline * baseline)
    fail("R, T: the optical axes pass " + std::to_string(a.gap_mm) +
         " mm apart (more than 0.1 x the " + std::to_string(baseline) +
         " mm baseline); both cameras must aim at the head");
  if (a.front_depth_mm <= 0 || a.side_depth_mm <= 0)
    fail("R, T: the optical axes meet behind a camera (depth front " +
         std::to_string(a.front_depth_mm) + " mm, side " + std::to_string(a.side_depth_mm) +
         " mm)");
  RigCalibration rig;
  rig.front = front;
  rig.side = side;
  rig.front.cam_from_head = a.front_from_head;
  rig.side.cam_from_head = side_from_front * a.front_from_head;
  for (const auto* c : {&rig.front, &rig.side})
    if (const std::string p = camera_problem(*c); !p.empty())
      fail(std::string(c == &rig.front ? "K1/D1" : "K2/D2") + ": " + p);
  return rig;
}

void write_opencv_stereo(const RigCalibration& rig, const std::string& path) {
  for (const auto* c : {&rig.front, &rig.side}) {
    const std::string which = c == &rig.front ? "front" : "side";
    if (c->projection != Projection::Perspective)
      throw std::invalid_argument("write_opencv_stereo: the " + which +
                                  " camera is orthographic; the OpenCV stereo form holds pinhole "
                                  "cameras only (write our own rig format instead)");
    if (const std::string p = camera_problem(*c); !p.empty())
      throw std::invalid_argument("write_opencv_stereo: the " + which + " camera: " + p);
  }
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw std::runtime_error("cannot write rig file " + path + ": folder " + parent.string() +
                             " does not exist");
  const Eigen::Isometry3d side_from_front =
      rig.side.cam_from_head * rig.front.cam_from_head.inverse();
  auto k_of = [](const CameraModel& c) {
    return cv::Mat((cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1));
  };
  auto d_of = [](const CameraModel& c) {
    std::vector<double> d = c.distortion;
    d.resize(5, 0.0);
    return cv::Mat(d, true).reshape(1, 1);
  };
  write_rig_text(path, [&](cv::FileStorage& fs) {
    fs.writeComment(
        "OpenCV stereo calibration (orthoface): camera 1 = front, camera 2 = side; x2 = R x1 + T, "
        "T in mm. orthoface_cam1_from_head places the head frame (orthoface DESIGN.md).");
    fs << "image_size" << cv::Size(rig.front.width, rig.front.height);
    if (rig.side.width != rig.front.width || rig.side.height != rig.front.height)
      fs << "image_size_2" << cv::Size(rig.side.width, rig.side.height);
    fs << "K1" << k_of(rig.front) << "D1" << d_of(rig.front);
    fs << "K2" << k_of(rig.side) << "D2" << d_of(rig.side);
    cv::Mat r, t, pose;
    cv::eigen2cv(Eigen::Matrix3d(side_from_front.linear()), r);
    cv::eigen2cv(Eigen::Vector3d(side_from_front.translation()), t);
    cv::eigen2cv(Eigen::Matrix4d(rig.front.cam_from_head.matrix()), pose);
    fs << "R" << r << "T" << t << "orthoface_cam1_from_head" << pose;
  });
}

RigCalibration read_opencv_stereo(const std::string& path) {
  return opencv_stereo_rig(read_rig_text(path), path);
}

RigCalibration opencv_stereo_rig(const RigNode& fs, const std::string& path) {
  const Fail fail = [&](const std::string& field, const std::string& what) {
    throw std::runtime_error("rig file " + path + " (OpenCV stereo calibration): " + field + ": " +
                             what);
  };
  CameraModel front = read_camera(fs, 1, fail), side = read_camera(fs, 2, fail);
  if (!read_size(fs, {"image_size", "imageSize"}, "image_width", "image_height", front.width,
                 front.height, fail))
    fail("image_size", "missing (image_size or imageSize [w, h], or image_width + image_height)");
  side.width = front.width, side.height = front.height;
  read_size(fs, {"image_size_2"}, "image_width_2", "image_height_2", side.width, side.height, fail);
  for (const auto* c : {&front, &side})
    if (c->width <= 0 || c->height <= 0 || c->width > 20000 || c->height > 20000)
      fail(c == &front ? "image_size" : "image_size_2",
           std::to_string(c->width) + "x" + std::to_string(c->height) + " is not in 1..20000");
  const Eigen::Isometry3d side_from_front = read_pose(fs, fail);
  RigCalibration rig;
  if (fs.find("orthoface_cam1_from_head")) {
    const cv::Mat m = read_mat(fs, "orthoface_cam1_from_head", "", fail);
    if (m.rows != 4 || m.cols != 4) fail("orthoface_cam1_from_head", "must be 4x4");
    Eigen::Matrix4d e;
    cv::cv2eigen(m, e);
    if (!is_rotation(e.topLeftCorner<3, 3>()) || e.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
      fail("orthoface_cam1_from_head", "is not a rigid motion");
    rig.front = front, rig.side = side;
    rig.front.cam_from_head.matrix() = e;
    rig.side.cam_from_head = side_from_front * rig.front.cam_from_head;
    for (const auto* c : {&rig.front, &rig.side})
      if (const std::string p = camera_problem(*c); !p.empty())
        fail(c == &rig.front ? "K1/D1" : "K2/D2", p);
  } else {
    try {
      rig = rig_from_stereo(front, side, side_from_front);
    } catch (const std::invalid_argument& e) {
      const std::string what = std::string(e.what()).substr(std::string("stereo rig: ").size());
      const size_t colon = what.find(": ");
      fail(what.substr(0, colon), what.substr(colon + 2));
    }
  }
  rig.source = path;
  return rig;
}

}  // namespace orthoface::capture
