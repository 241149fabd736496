#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::analysis {

// A named 3D point (mesh units), e.g. an MPEG-4 feature point "9.3" or a landmark "nose_tip".
struct FeaturePoint {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// Spherical coordinates of seed 001 eqs. 1-3: rho = |p|, phi = polar angle from +z in [0, pi],
// theta = azimuth atan2(y, x) in (-pi, pi]. (The paper's theta = arccos(x / (rho sin phi)) folds
// y < 0 onto y > 0; atan2 equals it for y >= 0, as in Table I.) The origin maps to all zeros.
struct Spherical {
  double rho = 0, theta = 0, phi = 0;
};
Spherical to_spherical(const Eigen::Vector3d& p);

// Great-circle distance rho_a * c between the directions of a and b (seed 001 eqs. 7-9 with the
// polar angle used as a co-latitude, see segmentation.cpp), in the units of rho_a.
double haversine_distance(const Spherical& a, const Spherical& b);

struct SegmentationOptions {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // head centre (head frame: between ears)
  bool smooth_weights = false;  // also compute per-point weights falling off with geodesic distance
  double falloff = 25.0;        // Gaussian sigma of that falloff (mesh units)
  void check() const;           // throws std::invalid_argument on non-finite centre or falloff <= 0
};

// Weight-motion areas (seed 001): each vertex joins the feature point at the smallest
// great-circle distance around `centre`. count / percent are per point (Table V).
// weights (only with smooth_weights): weights[p][v] in [0, 1], summing to 1 over p at each
// vertex the falloff reaches (0 elsewhere). Throws std::invalid_argument on a malformed mesh,
// no points, repeated names or a non-finite point.
struct Segmentation {
  std::vector<int> label;  // per vertex: index into the points
  std::vector<int> count;
  std::vector<double> percent;
  std::vector<std::vector<double>> weights;
};
Segmentation segment_by_feature_points(const mesh::TriMesh& mesh,
                                       const std::vector<FeaturePoint>& points,
                                       const SegmentationOptions& options = {});

// Reads feature points from JSON: {"feature_points": [{"name": .., "position": [x, y, z]}, ..]}
// (what `orthoface features` writes; "points" is accepted too) or {"name": [x, y, z], ..}.
// Names must be MPEG-4 feature points or vision landmark names unless allow_any_names.
// Throws std::runtime_error naming the file and the unknown / malformed entries.
std::vector<FeaturePoint> read_feature_points(const std::string& path,
                                              bool allow_any_names = false);

}  // namespace orthoface::analysis
