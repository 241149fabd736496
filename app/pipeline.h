#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "model/adapt.h"
#include "model/stereo.h"
#include "vision/observation.h"
#include "vision/observe.h"

namespace orthoface::app {

// Without a rig file the scale comes from this: the front silhouette's width at eye height is
// taken to be the generic head's width there (model::generic_half_width, about 150 mm), and the
// side photo is matched to the front by its midline features (scale and row offset).
struct ReconstructOptions {
  std::optional<capture::RigCalibration> rig;  // calibrated / simulated rig; none = ideal rig
  vision::ObserveOptions observe;              // includes --side-camera
  model::StereoOptions stereo;
  model::AdaptOptions adapt;  // --method, --k
  void check() const;         // throws std::invalid_argument
};

struct ReconstructionReport {
  std::vector<std::pair<std::string, double>> stage_ms;  // in pipeline order
  std::vector<std::string> warnings;
  std::map<std::string, double> confidences;  // "front_boundary", "side_profile", "centre_line",
                                              // "feature:<name>"
  std::vector<std::string> features_found;    // observed landmark names with 3D data
  std::string scale_note;                     // where the scale came from
  std::string front_landmarker;               // the front features' detector that ran
  int landmarks_used = 0, folds_fixed = 0, folds_remaining = 0;
};

struct Reconstruction {
  vision::FaceObservation observation;
  mesh::TriMesh mesh;  // adapted base mesh, head frame mm; uvs into `texture` = the front photo
  std::map<std::string, Eigen::Vector3d> landmarks;  // head frame, mm
  capture::RigCalibration rig;                       // the rig used (written as rig.yaml)
  cv::Mat front, side;                               // the photos used
  ReconstructionReport report;
};

// Front + side photos -> observation (vision) -> stereo -> adapted mesh with the front photo as
// texture. Throws std::invalid_argument naming the input when the photos are unusable or the
// observation cannot be reconstructed (no silhouette / profile, inconsistent heights).
Reconstruction reconstruct(const cv::Mat& front, const cv::Mat& side,
                           const ReconstructOptions& options = {});

// The same from an observation already made (e.g. sim::truth_observation); photos may be empty
// (then there is no texture).
Reconstruction reconstruct_observation(const vision::FaceObservation& observation,
                                       const cv::Mat& front, const cv::Mat& side,
                                       const ReconstructOptions& options = {});

// Writes the reconstruction folder (DESIGN.md): head.obj head.mtl head.png, front.png,
// side.png, rig.yaml, landmarks.json, observation.json, report.json. Files are written into
// DIR.tmp/ first and moved into DIR only when all succeeded. Throws std::runtime_error naming
// the file that failed (DIR is then untouched).
void write_reconstruction(const Reconstruction& reconstruction, const std::string& dir);

// The named landmarks of a landmarks.json that write_reconstruction wrote (head frame, mm).
// Throws std::runtime_error naming the file when it cannot be read or is malformed.
std::map<std::string, Eigen::Vector3d> read_landmarks(const std::string& path);

}  // namespace orthoface::app
