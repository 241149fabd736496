#include "reconstruct/head_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace orthoface::reconstruct {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// The smoothing factor of an exponential filter at cutoff fc for a step dt (One-Euro, eq. 3).
double alpha(double cutoff_hz, double dt) {
  const double tau = 1.0 / (2 * kPi * cutoff_hz);
  return 1.0 / (1.0 + tau / dt);
}

cv::Mat grey_of(const cv::Mat& image) {
  if (image.channels() == 1) return image.clone();
  cv::Mat g;
  cv::cvtColor(image, g, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return g;
}

std::vector<cv::Point2f> to_cv(const std::vector<Eigen::Vector2d>& p) {
  std::vector<cv::Point2f> out;
  out.reserve(p.size());
  for (const auto& q : p) out.emplace_back(static_cast<float>(q.x()), static_cast<float>(q.y()));
  return out;
}

Eigen::Matrix3d rotation_of(const Eigen::Vector3d& w) {
  const double a = w.norm();
  if (a < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

Eigen::Vector3d vector_of(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.axis() * aa.angle();
}

}  // namespace

OneEuroFilter::OneEuroFilter(double min_cutoff_hz, double beta, double d_cutoff_hz)
    : min_cutoff_(min_cutoff_hz), beta_(beta), d_cutoff_(d_cutoff_hz) {
  require(std::isfinite(min_cutoff_hz) && min_cutoff_hz > 0,
          "OneEuroFilter: min_cutoff_hz must be > 0");
  require(std::isfinite(beta) && beta >= 0, "OneEuroFilter: beta must be >= 0");
  require(std::isfinite(d_cutoff_hz) && d_cutoff_hz > 0, "OneEuroFilter: d_cutoff_hz must be > 0");
}

double OneEuroFilter::filter(double value, double t_s) {
  require(std::isfinite(value) && std::isfinite(t_s), "OneEuroFilter: value or time not finite");
  if (!started_ || t_s <= t_) {
    started_ = true;
    x_ = value;
    dx_ = 0;
    t_ = t_s;
    return x_;
  }
  const double dt = t_s - t_;
  t_ = t_s;
  dx_ += alpha(d_cutoff_, dt) * ((value - x_) / dt - dx_);
  const double cutoff = min_cutoff_ + beta_ * std::abs(dx_);
  x_ += alpha(cutoff, dt) * (value - x_);
  return x_;
}

double HeadPose::yaw_deg() const {
  // R = Ry(yaw) Rx(pitch) Rz(roll): yaw from the rotated +z axis (the face's direction).
  const Eigen::Vector3d z = rotation.col(2);
  return std::atan2(z.x(), z.z()) * kDeg;
}
double HeadPose::pitch_deg() const {
  const Eigen::Vector3d z = rotation.col(2);
  return std::asin(std::clamp(z.y(), -1.0, 1.0)) * kDeg;
}
double HeadPose::roll_deg() const { return std::atan2(rotation(1, 0), rotation(1, 1)) * kDeg; }
double HeadPose::angle_to_deg(const HeadPose& other) const {
  return Eigen::AngleAxisd(rotation.transpose() * other.rotation).angle() * kDeg;
}

void TrackerOptions::check() const {
  require(max_points >= 8 && max_points <= 5000, "TrackerOptions: max_points must be in 8..5000");
  require(std::isfinite(min_spacing_px) && min_spacing_px >= 1 && min_spacing_px <= 100,
          "TrackerOptions: min_spacing_px must be in 1..100");
  require(std::isfinite(min_facing) && min_facing >= 0 && min_facing < 1,
          "TrackerOptions: min_facing must be in [0, 1)");
  require(min_inliers >= 6 && min_inliers <= max_points,
          "TrackerOptions: min_inliers must be in 6..max_points");
  require(std::isfinite(inlier_px) && inlier_px > 0, "TrackerOptions: inlier_px must be > 0");
  require(std::isfinite(max_rms_px) && max_rms_px > 0, "TrackerOptions: max_rms_px must be > 0");
  require(std::isfinite(max_turn_deg) && max_turn_deg > 0 && max_turn_deg <= 90,
          "TrackerOptions: max_turn_deg must be in (0, 90]");
  require(!std::isnan(min_height_mm) && min_height_mm < std::numeric_limits<double>::infinity(),
          "TrackerOptions: min_height_mm must be a number below +infinity");
  OneEuroFilter check_filter(min_cutoff_hz, beta);
}

struct HeadTracker::Flow {
  std::vector<int> model;                 // index into points_
  std::vector<Eigen::Vector2d> observed;  // where the frame shows it
};

HeadTracker::HeadTracker(const mesh::TriMesh& mesh, int face_vertices,
                         const capture::CameraModel& camera, const cv::Mat& reference,
                         const TrackerOptions& options)
    : options_(options), camera_(camera) {
  options_.check();
  require(!mesh.vertices.empty() && !mesh.triangles.empty(), "HeadTracker: the mesh is empty");
  const int nv = static_cast<int>(mesh.vertices.size());
  require(face_vertices >= 0 && face_vertices <= nv,
          "HeadTracker: face_vertices must be in 0..the mesh's vertex count");
  if (face_vertices == 0) face_vertices = nv;
  const std::string bad = capture::camera_problem(camera);
  require(bad.empty(), "HeadTracker: camera: " + bad);
  require(!reference.empty() && reference.depth() == CV_8U &&
              (reference.channels() == 1 || reference.channels() == 3 || reference.channels() == 4),
          "HeadTracker: the reference frame must be 8-bit grey, BGR or BGRA");
  require(reference.cols == camera.width && reference.rows == camera.height,
          "HeadTracker: the reference frame is " + std::to_string(reference.cols) + "x" +
              std::to_string(reference.rows) + ", the camera " + std::to_string(camera.width) +
              "x" + std::to_string(camera.height));
  for (const auto& v : mesh.vertices) require(v.allFinite(), "HeadTracker: a vertex is not finite");
  reference_ = grey_of(reference);

  // The face's triangles as the camera sees them: pixels, depth, normal.
  const Eigen::Vector3d toward = -capture::view_direction(camera);
  struct Tri {
    Eigen::Vector2d p[3];
    Eigen::Vector3d x[3], n;
    double z[3];
  };
  std::vector<Tri> tris;
  cv::Mat face(reference_.size(), CV_8U, cv::Scalar(0));
  for (const auto& t : mesh.triangles) {
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= nv || t[1] >= nv || t[2] >= nv)
      throw std::invalid_argument("HeadTracker: a triangle's vertex index is out of range");
    if (t[0] >= face_vertices || t[1] >= face_vertices || t[2] >= face_vertices) continue;
    if (std::max({mesh.vertices[t[0]].y(), mesh.vertices[t[1]].y(), mesh.vertices[t[2]].y()}) <
        options_.min_height_mm)
      continue;
    Tri tri;
    for (int k = 0; k < 3; ++k) {
      tri.x[k] = mesh.vertices[t[k]];
      tri.p[k] = capture::project(camera, tri.x[k]);
      tri.z[k] = capture::depth(camera, tri.x[k]);
    }
    const Eigen::Vector3d n = (tri.x[1] - tri.x[0]).cross(tri.x[2] - tri.x[0]);
    if (n.norm() < 1e-12 || !tri.p[0].allFinite() || !tri.p[1].allFinite() || !tri.p[2].allFinite())
      continue;
    tri.n = n.normalized();
    if (tri.n.dot(toward) < options_.min_facing) continue;
    std::vector<cv::Point> poly;
    for (const auto& p : tri.p) poly.emplace_back(cvRound(p.x()), cvRound(p.y()));
    cv::fillConvexPoly(face, poly, cv::Scalar(255));
    tris.push_back(tri);
  }
  require(!tris.empty(), "HeadTracker: no face triangle faces the camera");
  cv::erode(face, face, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));

  // The most textured face pixels (Shi-Tomasi), each lifted onto the nearest face triangle.
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(reference_, corners, options_.max_points * 2, 0.002,
                          options_.min_spacing_px, face, 5);
  for (const auto& c : corners) {
    const Eigen::Vector2d q(c.x, c.y);
    double best = std::numeric_limits<double>::infinity();
    Eigen::Vector3d hit, normal;
    for (const auto& tri : tris) {
      const Eigen::Vector2d e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0], d = q - tri.p[0];
      const double det = e1.x() * e2.y() - e1.y() * e2.x();
      if (std::abs(det) < 1e-9) continue;
      const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
      const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
      if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
      const double z = (1 - b1 - b2) * tri.z[0] + b1 * tri.z[1] + b2 * tri.z[2];
      if (z >= best) continue;
      best = z;
      hit = (1 - b1 - b2) * tri.x[0] + b1 * tri.x[1] + b2 * tri.x[2];
      normal = tri.n;
    }
    if (!std::isfinite(best) || hit.y() < options_.min_height_mm) continue;
    points_.push_back(hit);
    normals_.push_back(normal);
    if (static_cast<int>(points_.size()) >= options_.max_points) break;
  }
  require(static_cast<int>(points_.size()) >= options_.min_inliers,
          "HeadTracker: the reference frame shows " + std::to_string(points_.size()) +
              " textured face points, fewer than " + std::to_string(options_.min_inliers));
  reference_px_ = project_all(HeadPose{});
  for (auto& f : filters_) f = OneEuroFilter(options_.min_cutoff_hz, options_.beta);
  last_.tracked = true;  // the reference frame is the fit's pose
}

std::vector<Eigen::Vector2d> HeadTracker::project_all(const HeadPose& pose) const {
  std::vector<Eigen::Vector2d> px(points_.size());
  for (size_t i = 0; i < points_.size(); ++i)
    px[i] = capture::project(camera_, pose.apply(points_[i]));
  return px;
}

HeadTracker::Flow HeadTracker::follow(const cv::Mat& from,
                                      const std::vector<Eigen::Vector2d>& from_px,
                                      const cv::Mat& to,
                                      const std::vector<Eigen::Vector2d>& guess_px,
                                      const HeadPose& guess) const {
  // Only points the guessed pose shows facing the camera, inside both frames.
  const Eigen::Vector3d toward = -capture::view_direction(camera_);
  const cv::Rect2d inside(2, 2, to.cols - 4, to.rows - 4);
  std::vector<int> index;
  std::vector<Eigen::Vector2d> a, b;
  for (size_t i = 0; i < points_.size(); ++i) {
    if ((guess.rotation * normals_[i]).dot(toward) < 0.5 * options_.min_facing) continue;
    if (!from_px[i].allFinite() || !guess_px[i].allFinite()) continue;
    if (!inside.contains({from_px[i].x(), from_px[i].y()}) ||
        !inside.contains({guess_px[i].x(), guess_px[i].y()}))
      continue;
    index.push_back(static_cast<int>(i));
    a.push_back(from_px[i]);
    b.push_back(guess_px[i]);
  }
  Flow flow;
  if (index.empty()) return flow;
  std::vector<cv::Point2f> p0 = to_cv(a), p1 = to_cv(b), back = p0;
  std::vector<uchar> ok, ok_back;
  std::vector<float> err;
  const cv::Size window(15, 15);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.03);
  cv::calcOpticalFlowPyrLK(from, to, p0, p1, ok, err, window, 3, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  cv::calcOpticalFlowPyrLK(to, from, p1, back, ok_back, err, window, 3, stop,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t k = 0; k < index.size(); ++k) {
    // Forward-backward check (Kalal et al. 2010): a point that does not come back is lost.
    if (!ok[k] || !ok_back[k] || cv::norm(back[k] - p0[k]) > 1.0) continue;
    flow.model.push_back(index[k]);
    flow.observed.emplace_back(p1[k].x, p1[k].y);
  }
  return flow;
}

bool HeadTracker::solve(const Flow& flow, HeadPose& pose, int& inliers, double& rms) const {
  const int n = static_cast<int>(flow.model.size());
  inliers = 0;
  rms = 0;
  if (n < options_.min_inliers) return false;
  const auto residuals = [&](const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
    Eigen::VectorXd e(2 * n);
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d p = capture::project(camera_, r * points_[flow.model[k]] + t);
      e.segment<2>(2 * k) = p - flow.observed[k];
    }
    return e;
  };
  // Gauss-Newton with Huber weights (IRLS) on a rotation increment and the translation; a
  // little damping keeps the orthographic camera's unobservable depth still.
  constexpr double kHuber = 1.5;
  Eigen::Matrix3d r = pose.rotation;
  Eigen::Vector3d t = pose.translation_mm;
  Eigen::VectorXd e = residuals(r, t);
  for (int it = 0; it < 12; ++it) {
    if (!e.allFinite()) return false;
    Eigen::MatrixXd j(2 * n, 6);
    for (int c = 0; c < 6; ++c) {
      const double h = c < 3 ? 1e-5 : 1e-3;
      Eigen::Vector3d dw = Eigen::Vector3d::Zero(), dt = Eigen::Vector3d::Zero();
      (c < 3 ? dw : dt)(c % 3) = h;
      j.col(c) = (residuals(rotation_of(dw) * r, t + dt) - e) / h;
    }
    Eigen::VectorXd w(2 * n);
    for (int k = 0; k < n; ++k) {
      const double d = e.segment<2>(2 * k).norm();
      w(2 * k) = w(2 * k + 1) = d <= kHuber ? 1.0 : kHuber / d;
    }
    Eigen::Matrix<double, 6, 6> h = j.transpose() * w.asDiagonal() * j;
    h.diagonal().array() += 1e-6 * (h.diagonal().maxCoeff() + 1.0);
    const Eigen::Matrix<double, 6, 1> g = j.transpose() * w.asDiagonal() * e;
    const Eigen::Matrix<double, 6, 1> step = -h.ldlt().solve(g);
    if (!step.allFinite()) return false;
    r = rotation_of(step.head<3>()) * r;
    t += step.tail<3>();
    e = residuals(r, t);
    if (step.head<3>().norm() < 1e-7 && step.tail<3>().norm() < 1e-4) break;
  }
  double sum = 0;
  for (int k = 0; k < n; ++k) {
    const double d = e.segment<2>(2 * k).norm();
    if (d > options_.inlier_px) continue;
    ++inliers;
    sum += d * d;
  }
  rms = inliers > 0 ? std::sqrt(sum / inliers) : 0;
  pose.rotation = r;
  pose.translation_mm = t;
  return true;
}

TrackResult HeadTracker::track(const cv::Mat& frame, double t_s) {
  require(std::isfinite(t_s), "HeadTracker::track: the frame time is not finite");
  require(!frame.empty() && frame.depth() == CV_8U &&
              (frame.channels() == 1 || frame.channels() == 3 || frame.channels() == 4),
          "HeadTracker::track: the frame must be 8-bit grey, BGR or BGRA");
  require(frame.cols == reference_.cols && frame.rows == reference_.rows,
          "HeadTracker::track: the frame is " + std::to_string(frame.cols) + "x" +
              std::to_string(frame.rows) + ", the camera " + std::to_string(reference_.cols) + "x" +
              std::to_string(reference_.rows));
  const cv::Mat grey = grey_of(frame);
  const bool was_tracked = last_.tracked;

  // Where to start: the previous frame's pose, or, when lost, the last good pose and the fit's.
  std::vector<HeadPose> guesses{was_tracked ? previous_raw_ : last_.pose};
  if (!was_tracked) {
    guesses.push_back(HeadPose{});
    // And a few turned poses a frame, in turn: a head that was already turned when it was lost
    // (or when the fit finished) is too far from both for the flow to find it.
    static const double kSearch[][2] = {{12, 0},  {-12, 0},  {24, 0},   {-24, 0},  {0, 10},
                                        {0, -10}, {12, 10},  {-12, 10}, {12, -10}, {-12, -10},
                                        {24, 10}, {-24, 10}, {24, -10}, {-24, -10}};
    constexpr int kCount = sizeof(kSearch) / sizeof(kSearch[0]);
    for (int i = 0; i < 3; ++i, search_ = (search_ + 1) % kCount) {
      HeadPose h;
      h.rotation = (Eigen::AngleAxisd(kSearch[search_][0] / kDeg, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(-kSearch[search_][1] / kDeg, Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
      guesses.push_back(h);
    }
  }
  TrackResult result;
  result.reason = "no model point followed";
  for (const HeadPose& guess : guesses) {
    const auto guess_px = project_all(guess);
    Flow flow = follow(reference_, reference_px_, grey, guess_px, guess);
    if (was_tracked && !previous_.empty()) {
      Flow recent = follow(previous_, project_all(previous_raw_), grey, guess_px, guess);
      flow.model.insert(flow.model.end(), recent.model.begin(), recent.model.end());
      flow.observed.insert(flow.observed.end(), recent.observed.begin(), recent.observed.end());
    }
    HeadPose pose = guess;
    int inliers = 0;
    double rms = 0;
    result.points = static_cast<int>(flow.model.size());
    if (!solve(flow, pose, inliers, rms)) {
      result.reason = std::to_string(flow.model.size()) + " model points followed, fewer than " +
                      std::to_string(options_.min_inliers);
      continue;
    }
    result.inliers = inliers;
    result.rms_px = rms;
    const double turn = pose.angle_to_deg(HeadPose{});
    if (inliers < options_.min_inliers) {
      result.reason = std::to_string(inliers) + " points agree with the pose, fewer than " +
                      std::to_string(options_.min_inliers);
    } else if (rms > options_.max_rms_px) {
      result.reason = "the points disagree with the pose (RMS " + std::to_string(rms) + " px)";
    } else if (!(turn <= options_.max_turn_deg)) {
      result.reason = "the pose turned " + std::to_string(turn) + " deg from the fit";
    } else {
      result.tracked = true;
      result.reason.clear();
      result.raw = pose;
      break;
    }
  }
  previous_ = grey;
  if (!result.tracked) {
    result.pose = last_.pose;
    last_ = result;
    return result;
  }
  previous_raw_ = result.raw;
  if (!was_tracked)
    for (auto& f : filters_) f.reset();
  const Eigen::Vector3d w = vector_of(result.raw.rotation) * kDeg;
  Eigen::Vector3d fw, ft;
  for (int c = 0; c < 3; ++c) {
    fw(c) = filters_[c].filter(w(c), t_s);
    ft(c) = filters_[3 + c].filter(result.raw.translation_mm(c), t_s);
  }
  result.pose.rotation = rotation_of(fw / kDeg);
  result.pose.translation_mm = ft;
  last_ = result;
  return result;
}

}  // namespace orthoface::reconstruct
