#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::analysis {

struct SimilarityOptions {
  int iso_geodesics = 8;      // n iso-geodesics (seed 003 §4.2: 8)
  int radial_geodesics = 16;  // m geodesics from the nose tip at equal angles (§4.3)
  double radius = 80.0;       // outermost iso-geodesic (mesh units) unless a boundary is closer
  double w0 = 100, w1 = 10, w2 = 1;    // ring weights of eq. 16
  Eigen::Vector3d view_axis{0, 0, 1};  // standard pose: the nose tip is the max along this (§4.1)
  Eigen::Vector3d up_axis{0, 1, 0};    // direction of the first geodesic (toward the brows)
  void check() const;                  // throws std::invalid_argument naming the bad field
};

// The correspondence network of one face (seed 003 §4-5) and its four ring-averaged metrics.
// network[i * n + j] = vertex where geodesic i meets iso-geodesic j (mesh indices).
struct FaceSignature {
  int nose_tip = -1;
  double width = 0.0;  // spacing of the iso-geodesics
  std::vector<int> network;
  std::vector<Eigen::Vector3d> network_points;  // exact crossing points on the surface
  std::vector<double> mean, gaussian, shape_index, curvedness;  // one per network point
  std::vector<std::string> warnings;
};

// Builds the network and the metrics. Throws std::invalid_argument on a malformed mesh (NaN,
// no triangles) or bad options, std::runtime_error when the surface around the nose tip is too
// small for the network (e.g. a boundary right next to it).
FaceSignature face_signature(const mesh::TriMesh& mesh, const SimilarityOptions& options = {});

// What makes `s` unfit for similarity(), or "" when it is fit: no network points, a metric
// that is not finite somewhere, or one that is the same at every network point (a sphere or a
// plane: a correlation with it is undefined). Two signatures of the same options that both give
// "" always score finite numbers in [0, 1].
std::string signature_problem(const FaceSignature& s);

// |Pearson correlation| of each metric over corresponding network points (seed 003 eq. 17),
// in [0, 1]; NaN for a metric that is constant on either face (e.g. a sphere; see
// signature_problem). Throws std::invalid_argument when the networks differ in size.
struct SimilarityScores {
  double mean = 0, gaussian = 0, shape_index = 0, curvedness = 0;
};
SimilarityScores similarity(const FaceSignature& a, const FaceSignature& b);

}  // namespace orthoface::analysis
