#pragma once
// The face's flanks set back where the two photos agree. Where both photos see the face (the
// cheeks and temples, whose normals lie between the two cameras) a surface point must show the
// same thing in each: its pixel in the front photo and its pixel in the side photo. The front
// photo fixes a point's x and y whatever its depth; the side photo's pixel moves with the depth,
// so the depth that makes the two agree best is the photos' own measure of it (photo
// consistency, as in multi-view stereo: Seitz et al. 2006, "A comparison and evaluation of
// multi-view stereo reconstruction algorithms", §2.1). The adapted mesh's flanks come from the
// base mesh's shape between the profile and the silhouette, and on real faces they stand too far
// forward (docs/views_accuracy.md): a side photo's nose then lands on the model's cheek and a
// turned view shows two noses. One offset for the whole face, found by a 1-D search, moves the
// flanks back along the front camera's axis, tapered to nothing at the midline and at the
// outline, which the profile and the silhouette fix. The face above the nose tip and the face
// below it take an offset each (the lower face of the base mesh stands further forward on real
// faces than the upper: docs/views_accuracy.md), blended across the nose tip's height.

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::reconstruct {

struct FlankDepthOptions {
  double min_mm = -6, max_mm = 8;  // offsets searched (> 0 moves the flanks back)
  double step_mm = 1;
  // The agreement (a correlation) must rise by this much over the unmoved mesh's, else nothing
  // moves: a face the photos do not resolve stays as the model made it.
  double min_gain = 0.05;
  // A point counts as seen by both photos when its normal is within acos(min_cos) of both
  // cameras' directions.
  double min_cos = 0.35;
  // The grey levels compared are band-passed: detail from fine_mm to coarse_mm on the face
  // (the two photos' shading of a flank differs, its features do not).
  double fine_mm = 1.2, coarse_mm = 6;
  int min_points = 60;  // fewer points seen by both: nothing moves
  // An offset each above and below the nose tip, blended over +-blend_mm of its height; the
  // offset below searched up to below_max_mm. Off: one offset for the whole face.
  bool bands = true;
  double blend_mm = 10;
  double below_max_mm = 6;
  void check() const;  // throws std::invalid_argument naming the field
};

struct FlankDepth {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double offset_mm = 0;            // chosen offset above the nose tip (0 when nothing moved)
  double offset_below_mm = 0;      // below it (offset_mm when the options' bands are off)
  double agreement_before = kNaN;  // correlation of the two photos at offset 0
  double agreement_after = kNaN;   // at the chosen offsets
  int points = 0;                  // surface points both photos see
  std::vector<double> weight;      // per vertex 0..1: the share of the offset it moves
  std::vector<double> below;       // per vertex 0..1: the share of that taken from offset_below_mm
  // Vertex i's move back in mm.
  double shift(size_t i) const {
    return weight[i] * ((1 - below[i]) * offset_mm + below[i] * offset_below_mm);
  }
};

// Finds the offset for `mesh` (head frame mm, outward normals) seen by `rig` (the photo rig:
// the side camera where it stood) in the two photos (8-bit BGR or grey, the rig's sizes).
// Throws std::invalid_argument on an empty mesh, or photos of other sizes than the rig's or of
// another pixel type.
FlankDepth fit_flank_depth(const mesh::TriMesh& mesh, const cv::Mat& front, const cv::Mat& side,
                           const capture::RigCalibration& rig,
                           const FlankDepthOptions& options = {});

// Moves the mesh's vertices (and each landmark with its nearest vertex) back along the front
// camera's axis by depth.shift(i). Throws std::invalid_argument when the weights do not match
// the mesh.
void move_flanks(const FlankDepth& depth, const capture::CameraModel& front_camera,
                 mesh::TriMesh& mesh, std::map<std::string, Eigen::Vector3d>& landmarks);

}  // namespace orthoface::reconstruct
