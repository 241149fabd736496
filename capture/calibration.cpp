#include "capture/calibration.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/stereo_rig.h"

namespace orthoface::capture {
namespace {

std::vector<cv::Point3f> board_points(const Checkerboard& b) {
  std::vector<cv::Point3f> p;
  for (int r = 0; r < b.rows; ++r)
    for (int c = 0; c < b.cols; ++c)
      p.emplace_back(float(c * b.square_mm), float(r * b.square_mm), 0.f);
  return p;
}

struct Views {
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> index;  // which input pair each came from
};

struct Intrinsics {
  cv::Mat k, d;
  double rms = 0;
};

Intrinsics calibrate_one(const Views& v, const Checkerboard& b, cv::Size size) {
  std::vector<std::vector<cv::Point3f>> obj(v.corners.size(), board_points(b));
  Intrinsics in;
  std::vector<cv::Mat> rv, tv;
  // k1, k2 only: webcam lenses rarely need more, and tangential terms trade off against the
  // principal point when the views are few.
  in.rms = cv::calibrateCamera(obj, v.corners, size, in.k, in.d, rv, tv,
                               cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST);
  return in;
}

CameraModel to_model(const Intrinsics& in, cv::Size size) {
  CameraModel m;
  m.projection = Projection::Perspective;
  m.width = size.width;
  m.height = size.height;
  m.fx = in.k.at<double>(0, 0);
  m.fy = in.k.at<double>(1, 1);
  m.cx = in.k.at<double>(0, 2);
  m.cy = in.k.at<double>(1, 2);
  m.distortion.assign(in.d.begin<double>(), in.d.end<double>());
  return m;
}

Eigen::Isometry3d to_iso(const cv::Mat& r, const cv::Mat& t) {
  Eigen::Matrix3d R;
  Eigen::Vector3d T;
  cv::Mat rm = r.rows == 3 && r.cols == 3 ? r : cv::Mat();
  if (rm.empty()) cv::Rodrigues(r, rm);
  cv::cv2eigen(rm, R);
  cv::cv2eigen(t.reshape(1, 3), T);
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = R;
  iso.translation() = T;
  return iso;
}

// Predicted sd (mm) of the side_from_front translation from the shared views: Gauss-Newton
// covariance of the side camera's reprojection in the 6 pose parameters, corner noise sigma.
Eigen::Vector3d translation_sd(const std::vector<Eigen::Isometry3d>& front_from_board,
                               const Eigen::Isometry3d& side_from_front, const CameraModel& side,
                               const Checkerboard& b, double sigma) {
  const auto pts = board_points(b);
  auto residuals = [&](const Eigen::Matrix<double, 6, 1>& d) {
    Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w = d.head<3>();
    if (w.norm() > 0) delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).matrix();
    delta.translation() = d.tail<3>();
    const Eigen::Isometry3d s_f = side_from_front * delta;  // perturbation in front axes
    std::vector<double> r;
    for (const auto& f_b : front_from_board)
      for (const auto& p : pts) {
        const Eigen::Vector3d q = s_f * (f_b * Eigen::Vector3d(p.x, p.y, p.z));
        r.push_back(side.fx * q.x() / q.z());
        r.push_back(side.fy * q.y() / q.z());
      }
    return r;
  };
  const std::vector<double> r0 = residuals(Eigen::Matrix<double, 6, 1>::Zero());
  Eigen::MatrixXd J(r0.size(), 6);
  for (int j = 0; j < 6; ++j) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d[j] = j < 3 ? 1e-6 : 1e-4;
    const std::vector<double> r1 = residuals(d);
    for (size_t i = 0; i < r0.size(); ++i) J(long(i), j) = (r1[i] - r0[i]) / d[j];
  }
  const Eigen::Matrix<double, 6, 6> info = J.transpose() * J;
  const Eigen::Matrix<double, 6, 6> cov =
      sigma * sigma * info.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::Vector3d sd;
  for (int i = 0; i < 3; ++i) sd[i] = std::sqrt(std::max(0.0, cov(3 + i, 3 + i)));
  if (info.fullPivLu().rank() < 6) sd.setConstant(std::numeric_limits<double>::infinity());
  return sd;
}

}  // namespace

void Checkerboard::check() const {
  if (cols < 3 || rows < 3 || cols > 64 || rows > 64)
    throw std::invalid_argument("Checkerboard: cols and rows (inner corners) must be in 3..64");
  if ((cols + rows) % 2 == 0)
    throw std::invalid_argument(
        "Checkerboard: cols + rows must be odd (e.g. 9x6), or the board's "
        "orientation is ambiguous");
  if (!(square_mm > 0 && square_mm < 1000))
    throw std::invalid_argument("Checkerboard: square_mm must be in (0, 1000)");
}

void CalibrationOptions::check() const {
  board.check();
  if (min_views < 3) throw std::invalid_argument("CalibrationOptions: min_views must be >= 3");
  if (min_shared_views < 1)
    throw std::invalid_argument("CalibrationOptions: min_shared_views must be >= 1");
  if (!(pixel_noise > 0))
    throw std::invalid_argument("CalibrationOptions: pixel_noise must be > 0");
  if (!(max_translation_sd_mm > 0))
    throw std::invalid_argument("CalibrationOptions: max_translation_sd_mm must be > 0");
}

std::optional<std::vector<cv::Point2f>> find_board(const cv::Mat& image,
                                                   const Checkerboard& board) {
  board.check();
  if (image.empty()) throw std::invalid_argument("find_board: empty image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Point2f> corners;
  const cv::Size pattern(board.cols, board.rows);
  if (!cv::findChessboardCorners(grey, pattern, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
    return std::nullopt;
  cv::cornerSubPix(grey, corners, {5, 5}, {-1, -1},
                   {cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001});
  // findChessboardCorners may also return a mirrored numbering (rows swapped) at grazing angles.
  // Seen from its printed side the board keeps its handedness: x cross y points into the image.
  const cv::Point2f dx = corners[1] - corners[0], dy = corners[board.cols] - corners[0];
  if (dx.x * dy.y - dx.y * dy.x < 0)
    for (int r = 0; r < board.rows / 2; ++r)
      std::swap_ranges(corners.begin() + r * board.cols, corners.begin() + (r + 1) * board.cols,
                       corners.begin() + (board.rows - 1 - r) * board.cols);
  // findChessboardCorners may start from either end (a 180 deg turn of the board). Make corner 0
  // the one whose outer corner square is dark, so every view of one board numbers it alike
  // (needs cols + rows odd: then the two ends' corner squares differ in colour).
  if ((board.cols + board.rows) % 2 == 1) {
    const cv::Point2f outward = corners[0] + 0.5f * (corners[0] - corners[board.cols + 1]);
    const cv::Point2f inward = corners[0] + 0.5f * (corners[board.cols + 1] - corners[0]);
    auto level = [&grey](cv::Point2f p) {
      const int x = std::clamp(int(p.x), 0, grey.cols - 1),
                y = std::clamp(int(p.y), 0, grey.rows - 1);
      return int(grey.at<unsigned char>(y, x));
    };
    if (level(outward) > level(inward)) std::reverse(corners.begin(), corners.end());
  }
  // OpenCV's corner coordinates put pixel centres at integers; ours at +0.5.
  for (auto& c : corners) c += cv::Point2f(0.5f, 0.5f);
  return corners;
}

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::AngleAxisd d(a.linear().transpose() * b.linear());
  return std::abs(d.angle()) * 180.0 / M_PI;
}

namespace {

void check_inputs(const std::vector<cv::Mat>& front, const std::vector<cv::Mat>& side) {
  if (front.size() != side.size())
    throw std::invalid_argument("calibrate_rig: " + std::to_string(front.size()) +
                                " front images but " + std::to_string(side.size()) + " side");
  if (front.empty()) throw std::invalid_argument("calibrate_rig: no images");
  for (size_t i = 0; i < front.size(); ++i) {
    if (front[i].empty() || side[i].empty())
      throw std::invalid_argument("calibrate_rig: image pair " + std::to_string(i) + " is empty");
    if (front[i].size() != front[0].size() || side[i].size() != side[0].size())
      throw std::invalid_argument("calibrate_rig: image pair " + std::to_string(i) +
                                  " differs in size from the first");
  }
}

void require_views(int found, int needed, const std::string& where, const Checkerboard& b) {
  if (found >= needed) return;
  throw std::runtime_error("calibrate: the " + std::to_string(b.cols) + "x" +
                           std::to_string(b.rows) + " board is fully visible in " +
                           std::to_string(found) + " " + where + "; need at least " +
                           std::to_string(needed) + " (take more views)");
}

const char* kAxisNames[3] = {"x (front image right)", "y (front image down)",
                             "z (front viewing direction)"};

}  // namespace

RigCalibrationReport calibrate_rig(const std::vector<cv::Mat>& front,
                                   const std::vector<cv::Mat>& side,
                                   const CalibrationOptions& options) {
  options.check();
  check_inputs(front, side);
  const Checkerboard& b = options.board;
  Views fv, sv;
  std::vector<int> shared_f, shared_s;  // positions in fv / sv of the shared views
  for (size_t i = 0; i < front.size(); ++i) {
    auto f = find_board(front[i], b);
    auto s = find_board(side[i], b);
    if (f && s)
      shared_f.push_back(int(fv.corners.size())), shared_s.push_back(int(sv.corners.size()));
    if (f) fv.corners.push_back(*f), fv.index.push_back(int(i));
    if (s) sv.corners.push_back(*s), sv.index.push_back(int(i));
  }
  require_views(int(fv.corners.size()), options.min_views, "front images", b);
  require_views(int(sv.corners.size()), options.min_views, "side images", b);
  require_views(int(shared_f.size()), options.min_shared_views,
                "pairs seen by both cameras (hold it at about 45 deg between them)", b);
  RigCalibrationReport rep;
  rep.views_front = int(fv.corners.size());
  rep.views_side = int(sv.corners.size());
  rep.views_shared = int(shared_f.size());
  const Intrinsics fi = calibrate_one(fv, b, front[0].size());
  const Intrinsics si = calibrate_one(sv, b, side[0].size());
  rep.rms_front_px = fi.rms;
  rep.rms_side_px = si.rms;
  std::vector<std::vector<cv::Point2f>> cf, cs;
  for (size_t k = 0; k < shared_f.size(); ++k)
    cf.push_back(fv.corners[shared_f[k]]), cs.push_back(sv.corners[shared_s[k]]);
  std::vector<std::vector<cv::Point3f>> obj(cf.size(), board_points(b));
  cv::Mat kf = fi.k.clone(), df = fi.d.clone(), ks = si.k.clone(), ds = si.d.clone(), R, T, E, F;
  // Joint refinement: the shared views also constrain both cameras' intrinsics.
  rep.rms_stereo_px = cv::stereoCalibrate(
      obj, cf, cs, kf, df, ks, ds, front[0].size(), R, T, E, F,
      cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_FIX_K3 | cv::CALIB_ZERO_TANGENT_DIST);
  rep.side_from_front = to_iso(R, T);
  rep.rig.front = to_model({kf, df, fi.rms}, front[0].size());
  rep.rig.side = to_model({ks, ds, si.rms}, side[0].size());
  std::vector<Eigen::Isometry3d> front_from_board;
  for (const auto& c : cf) {
    cv::Mat rv, tv;
    cv::solvePnP(board_points(b), c, kf, df, rv, tv);
    front_from_board.push_back(to_iso(rv, tv));
  }
  rep.translation_sd_mm =
      translation_sd(front_from_board, rep.side_from_front, rep.rig.side, b, options.pixel_noise);
  for (int a = 0; a < 3; ++a)
    if (!(rep.translation_sd_mm[a] <= options.max_translation_sd_mm))
      throw std::runtime_error(
          "calibrate: the side camera's position along " + std::string(kAxisNames[a]) +
          " is not constrained by the " + std::to_string(rep.views_shared) +
          " shared view(s) (predicted sd " + std::to_string(rep.translation_sd_mm[a]) +
          " mm); take more views seen by both cameras, at other positions and angles");
  const Eigen::Isometry3d f_h = stereo_axes(rep.side_from_front).front_from_head;
  rep.rig.front.cam_from_head = f_h;
  rep.rig.side.cam_from_head = rep.side_from_front * f_h;
  rep.rig.source = "calibrated from " + std::to_string(front.size()) + " image pairs";
  for (double rms : {rep.rms_front_px, rep.rms_side_px, rep.rms_stereo_px})
    if (rms > 1.0)
      rep.warnings.push_back("reprojection error " + std::to_string(rms) + " px > 1 px");
  return rep;
}

}  // namespace orthoface::capture
