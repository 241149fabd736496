// The head's pose in a live camera, frame after frame, against a fitted model: model points
// tracked by optical flow and the pose solved from them, then smoothed by a One-Euro filter.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::reconstruct {

// One-Euro filter (Casiez, Roussel and Vogel, CHI 2012): a low-pass filter whose cutoff rises
// with the signal's speed, fc = min_cutoff + beta * |dx/dt| (their eq. 4), so a head at rest is
// steady and a moving head lags little.
class OneEuroFilter {
 public:
  // Cutoffs in Hz (> 0, finite), beta >= 0; else std::invalid_argument naming the value.
  explicit OneEuroFilter(double min_cutoff_hz = 1.0, double beta = 0.0, double d_cutoff_hz = 1.0);
  // The filtered value of `value` sampled at time t_s (seconds). The first sample, or one not
  // later than the previous, is passed through and restarts the filter. A non-finite value or
  // time is std::invalid_argument.
  double filter(double value, double t_s);
  void reset() { started_ = false; }

 private:
  double min_cutoff_, beta_, d_cutoff_;
  bool started_ = false;
  double x_ = 0, dx_ = 0, t_ = 0;
};

// A rigid motion of the head in its own frame (mm): a model point X is seen at R X + t. The
// identity is the pose of the frame the model was fitted from.
struct HeadPose {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return rotation * x + translation_mm; }
  // The rotation's angles in degrees, head frame: yaw about +y (> 0 turns the face toward the
  // head's +x, the subject's left), pitch about +x (> 0 lifts the chin), roll about +z.
  double yaw_deg() const;
  double pitch_deg() const;
  double roll_deg() const;
  // The angle of the rotation between this pose and `other`, degrees.
  double angle_to_deg(const HeadPose& other) const;
};

struct TrackerOptions {
  int max_points = 240;       // model points tracked (the most textured of the face)
  double min_spacing_px = 6;  // between chosen points in the reference frame
  double min_facing = 0.3;    // cos of the angle between a point's normal and the view
  int min_inliers = 25;       // fewer points that agree with the pose: the head is lost
  double inlier_px = 3.0;     // residual of a point that agrees
  double max_rms_px = 2.0;    // inlier RMS above this: the head is lost
  double max_turn_deg = 45;   // a pose turned further from the fit than this: lost
  // Model points lower than this (head frame y, mm) are not tracked: LiveView sets the lips'
  // line (between lip_upper and lip_lower), as the lower lip and jaw move when the person talks.
  double min_height_mm = -std::numeric_limits<double>::infinity();
  double min_cutoff_hz = 1.0;  // One-Euro filter of the pose (each rotation-vector and
  double beta = 0.5;           // translation component; beta per degree or mm per second)
  void check() const;          // std::invalid_argument naming the first bad field
};

// What one frame gave. `pose` is the filtered pose (the last good one while lost), `raw` the
// frame's own solution (when tracked).
struct TrackResult {
  bool tracked = false;
  HeadPose pose, raw;
  int points = 0, inliers = 0;  // tracked by the flow / agreeing with the pose
  double rms_px = 0;            // inliers' reprojection RMS
  std::string reason;           // why the head is lost ("" when tracked)
};

// Tracks the head in one camera. The model's points are followed two ways at once: from the
// previous frame (appearance changes slowly) and from the reference frame (no drift), both
// seeded by where the predicted pose puts them (pyramidal Lucas-Kanade, forward-backward
// checked); the pose is the robust least-squares fit (Gauss-Newton, Huber weights) of the
// model points' projections to them, through capture::project, so orthographic and
// perspective cameras alike. When the head is lost it keeps the last good pose and tries again
// on every frame from there, from the fit's pose and from three of a ring of turned poses (yaw
// up to +-24 deg, pitch +-10), so it recovers without a restart.
class HeadTracker {
 public:
  // mesh: the fitted model (head frame, mm), its first `face_vertices` vertices the face (0 =
  // all); camera: the camera the frames come from; reference: the frame the model was fitted
  // from (8-bit, 1 or 3 channels, the camera's size), where the pose is the identity.
  // Throws std::invalid_argument naming the bad input (empty mesh, bad camera, wrong image
  // size / type, no textured face point visible).
  HeadTracker(const mesh::TriMesh& mesh, int face_vertices, const capture::CameraModel& camera,
              const cv::Mat& reference, const TrackerOptions& options = {});

  // The head in `frame` (same size and type as the reference) taken at t_s seconds (increasing).
  // Throws std::invalid_argument for a wrong frame or a non-finite time.
  TrackResult track(const cv::Mat& frame, double t_s);

  const HeadPose& pose() const { return last_.pose; }
  bool lost() const { return !last_.tracked; }
  int model_points() const { return static_cast<int>(points_.size()); }

 private:
  struct Flow;
  std::vector<Eigen::Vector2d> project_all(const HeadPose& pose) const;
  Flow follow(const cv::Mat& from, const std::vector<Eigen::Vector2d>& from_px, const cv::Mat& to,
              const std::vector<Eigen::Vector2d>& guess_px, const HeadPose& guess) const;
  bool solve(const Flow& flow, HeadPose& pose, int& inliers, double& rms) const;

  TrackerOptions options_;
  capture::CameraModel camera_;
  std::vector<Eigen::Vector3d> points_, normals_;  // the tracked model points and normals
  cv::Mat reference_, previous_;                   // grey
  std::vector<Eigen::Vector2d> reference_px_;
  HeadPose previous_raw_;
  TrackResult last_;
  int search_ = 0;  // the next turned pose tried while lost
  OneEuroFilter filters_[6];
};

}  // namespace orthoface::reconstruct
