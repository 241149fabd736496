#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::analysis {

struct FeatureOptions {
  double neighbourhood = 0.03;    // Euclidean radius of the ratio test, x pose_free_size
  double dense_area = 0.05;       // the highest-ratio fraction of the surface area is "dense"...
  double ratio_threshold = 1.08;  // ...but only where geodesic / Euclidean is above this
  double ratio_cap = 4.0;         // pairs not joined within cap x radius count as the cap
  int max_sources = 10000;        // ratio sources (a farthest-point sample above this)
  double plane_band = 0.012;      // half-width of the plane slices, x ear-to-ear distance
  void check() const;             // throws std::invalid_argument naming the bad field
};

// One found point: an MPEG-4 name ("9.3") or a helper name ("nasion"), its vertex and position.
struct FoundPoint {
  std::string name, description;
  int vertex = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// Seed 000's outputs: per-vertex ratio and clusters (z_clusters), the key vertices and local
// axes (z_repere), the feature points (z_fp), and what could not be found.
struct FeatureReport {
  std::vector<double> ratio;  // per vertex: max geodesic / Euclidean over close pairs (>= 1)
  std::vector<int> cluster;   // per vertex: dense cluster id (largest first), -1 elsewhere
  std::optional<int> ear_left, ear_right, nose_tip;  // key vertices P1, P2, P4 (subject's left)
  Eigen::Vector3d ear_midpoint = Eigen::Vector3d::Zero();  // P3
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();      // columns: left, up, forward (unit)
  bool axes_found = false;
  Eigen::Vector4d symmetry_plane = Eigen::Vector4d::Zero();  // n.p + d = 0, n = left axis
  double symmetry_error = 0.0;  // mean mirror distance / ear distance (0 = symmetric)
  std::vector<FoundPoint> points;
  std::vector<std::string> missing;  // "10.1: ...", one line per point or step not found
};

// Finds seed 000's key vertices and MPEG-4 feature points on a head mesh, independent of its
// position, orientation and scale: dense clusters where geodesic >> Euclidean (§VI.G), the two
// ears as the farthest symmetric cluster pair, the nose tip on their bisecting plane (§VI.H),
// then peaks and troughs of the mid-plane and the two side-plane profiles. A face without ears
// (front-half reconstruction) reports the ears and everything that needs them as missing.
// Vertex indices refer to `mesh`. Throws std::invalid_argument on a malformed mesh.
FeatureReport mpeg4_features(const mesh::TriMesh& mesh, const FeatureOptions& options = {});

// `report` of `mesh` as JSON text (features.json of `orthoface features`, `orthoface.features` in
// Python): key_vertices (P1_ear_left, P2_ear_right, P4_nose_tip as {vertex, position} or null;
// P3_ear_midpoint), axes and symmetry_plane when the ears were found, feature_points (name,
// description, vertex, position) and missing. Throws std::invalid_argument when a vertex index
// of `report` is outside `mesh`.
std::string feature_report_json(const mesh::TriMesh& mesh, const FeatureReport& report);

// Diagonal of the mesh's bounding box along its principal axes (the same in every pose): the
// length every relative option above is a fraction of. Throws std::invalid_argument on a bad mesh.
double pose_free_size(const mesh::TriMesh& mesh);

// Per-vertex ratio field alone (first step above). Throws std::invalid_argument on a bad mesh.
std::vector<double> geodesic_euclidean_ratio(const mesh::TriMesh& mesh,
                                             const FeatureOptions& options = {});

}  // namespace orthoface::analysis
