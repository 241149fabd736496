#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "capture/camera_model.h"
#include "vision/observation.h"

namespace orthoface::model {

struct StereoOptions {
  double warn_mismatch_px = 6.0;     // a feature whose views disagree by more is reported
  double reject_mismatch_px = 40.0;  // ... and by more than this is dropped (treated as missing)
  double min_height_overlap = 0.5;   // profile must cover this share of the silhouette's height
  void check() const;                // throws std::invalid_argument
};

// One 3D point from stereo matching, head frame (mm).
struct StereoPoint {
  Eigen::Vector3d head_mm = Eigen::Vector3d::Zero();
  bool has_depth = true;     // false: seen in the front view only, z is unknown (left 0)
  double confidence = 0.0;   // the lower of the two views' confidences
  double mismatch_px = 0.0;  // largest reprojection error of the matched point in either view
};

// What stereo matching gives the adaptation: the front silhouette and the side profile as
// head-frame curves, the centre line, and the named features in 3D.
struct StereoData {
  std::vector<Eigen::Vector2d> silhouette;  // front boundary, (x, y) mm on the plane z = 0
  std::vector<Eigen::Vector2d> profile;     // side boundary, (z, y) mm on the plane x = 0
  Eigen::Vector2d centre_point = Eigen::Vector2d::Zero();       // centre line: (x, y) mm on z = 0
  Eigen::Vector2d centre_direction = Eigen::Vector2d::UnitY();  // unit (dx, dy)
  std::map<std::string, StereoPoint> features;
  double y_top = 0.0, y_bottom = 0.0;  // heights covered by both silhouette and profile
  std::vector<std::string> warnings;   // disagreements between views, dropped features
};

// Seed 004 eq. 1 for the ideal rig (orthographic, shared row): front pixel -> x and y, side
// pixel column -> z; y is the mean of the two rows. For any other rig: the midpoint of the two
// viewing rays (triangulation, distortion removed). Result in the head frame, mm.
Eigen::Vector3d triangulate(const capture::RigCalibration& rig, const Eigen::Vector2d& front_px,
                            const Eigen::Vector2d& side_px);

// Where the viewing ray of pixel `px` of `camera` meets the head-frame plane z = z_mm.
Eigen::Vector3d point_at_depth(const capture::CameraModel& camera, const Eigen::Vector2d& px,
                               double z_mm);

// Stereo matching of an observation (seed 004 §4-5). The side view must already face left
// (observation.side_faces_left; otherwise its columns are mirrored here). Throws
// std::invalid_argument when a coordinate is not finite, a boundary has fewer than 3 points
// ("cannot reconstruct"), or the two views' heights do not overlap (inconsistent views).
StereoData stereo_match(const vision::FaceObservation& observation,
                        const capture::RigCalibration& rig, const StereoOptions& options = {});

// Outermost silhouette x at height y on one side (sign -1: subject's right, +1: left), or
// nullopt when the curve does not reach y. The most projecting profile z likewise.
std::optional<double> silhouette_x_at(const StereoData& data, double y_mm, int sign);
std::optional<double> profile_z_at(const StereoData& data, double y_mm);
// x of the centre line at height y.
double centre_x_at(const StereoData& data, double y_mm);

}  // namespace orthoface::model
