#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "model/adapt.h"

// Sub-steps of adapt() shared by adapt.cpp, adapt_steps.cpp and procrustes.cpp (not public API).
namespace orthoface::model::detail {

std::vector<Eigen::Vector3d> apply(const Alignment& a, const std::vector<Eigen::Vector3d>& v);

struct AlignedTargets {
  Alignment alignment;
  std::vector<Eigen::Vector3d> aligned;  // the base vertices under `alignment`
  LandmarkTargets targets;
};

// align_base, then landmark_targets. Features that landmark_targets drops as outliers (too far
// from the aligned base) would still pull the alignment's centre and spread, so when there are
// any both steps are repeated once without them. Warnings of both passes, without repeats.
AlignedTargets align_and_target(const BaseMesh& base, const StereoData& data,
                                const AdaptOptions& options, std::vector<std::string>* warnings);

std::vector<std::vector<int>> vertex_adjacency(const mesh::TriMesh& mesh);

// Aligned positions with the targets set and the others moved by NNWA (seed 002 eq. 3.9),
// except the vertices flagged in `skip` (one flag per vertex, or empty), which stay aligned.
// Throws std::invalid_argument when `skip` has another size.
std::vector<Eigen::Vector3d> move_by_nnwa(const std::vector<Eigen::Vector3d>& aligned,
                                          const LandmarkTargets& targets, int k,
                                          const std::vector<char>& skip = {});

// Aligned positions with the targets set and the others moved by seed 004 eq. 2 along their
// slice, between its centre-line vertex and its two extremes; an extreme without silhouette
// data is placed by NNWA first. Slices without a profile point fall back to NNWA.
std::vector<Eigen::Vector3d> move_by_interpolation(const BaseMesh& base,
                                                   const std::vector<Eigen::Vector3d>& aligned,
                                                   const LandmarkTargets& targets, int k);

// Smooths the displacement of free vertices within options.blend_rings of a feature target.
void blend_near_features(const std::vector<std::vector<int>>& adjacency,
                         const std::vector<Eigen::Vector3d>& aligned,
                         const LandmarkTargets& targets, const AdaptOptions& options,
                         std::vector<Eigen::Vector3d>& moved);

// The displacement of the free vertices smoothed in proportion to its roughness
// (AdaptOptions::smooth_iterations, rough_from_mm, rough_full_mm); `moved` is updated.
struct Smoothing {
  double roughness_mm = 0, share = 0;
};
Smoothing smooth_if_rough(const std::vector<std::vector<int>>& adjacency,
                          const std::vector<Eigen::Vector3d>& aligned,
                          const LandmarkTargets& targets, const AdaptOptions& options,
                          std::vector<Eigen::Vector3d>& moved);

// Relaxes vertices of triangles flipped against the same triangles on `reference` (vertex
// positions, same topology; free vertices first, then any) until none is flipped or the passes
// run out. Returns {folds found at the start, folds left}.
std::pair<int, int> remove_folds(const std::vector<std::vector<int>>& adjacency,
                                 const std::vector<Eigen::Vector3d>& reference,
                                 const LandmarkTargets& targets, int max_passes,
                                 mesh::TriMesh& mesh);

// Opens the fins a front feature leaves standing out of its slice: from the centre line to each
// extreme a slice's vertices are made to move outward (x never back toward the centre), so the
// front half of the face is seen from the front (+z) without a fold. Returns the vertices moved.
int open_slice_fins(const BaseMesh& base, mesh::TriMesh& mesh);

}  // namespace orthoface::model::detail
