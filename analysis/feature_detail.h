#pragma once
// Internal steps of mpeg4_features (seed 000 §VI.G-H), shared by its two .cpp files.

#include <vector>

#include <Eigen/Core>

#include "analysis/mpeg4_features.h"

namespace orthoface::analysis::detail {

// The head frame found so far: origin P3, unit axes, ear distance D.
struct LocalFrame {
  Eigen::Vector3d origin, left, up, forward;
  double ear_distance = 0.0;
};

// One profile sample: the surface point, its nearer mesh vertex, and its height along `up` and
// depth along `forward` (both from the origin).
struct ProfileSample {
  int vertex;
  double s, f;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// The section of the mesh by the plane left . (p - origin) = offset: its outermost (max f)
// point per height bin of width `band` (with the nearer vertex of the crossing edge), front half
// only (f > 0), sorted by height.
std::vector<ProfileSample> plane_profile(const mesh::TriMesh& mesh, const LocalFrame& frame,
                                         double offset, double band);

// Indices into `profile` of local maxima (peaks = true) or minima with at least `prominence`
// rise / drop on both sides within the profile.
std::vector<int> profile_extrema(const std::vector<ProfileSample>& profile, bool peaks,
                                 double prominence);

// Adds the mid-plane and side-plane MPEG-4 points (and lines to report.missing).
void profile_points(const mesh::TriMesh& mesh, const LocalFrame& frame,
                    const FeatureOptions& options, FeatureReport& report);

}  // namespace orthoface::analysis::detail
