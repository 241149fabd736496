#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::model {

// The face region where reconstructions are measured: the front of the head between forehead
// and chin, i.e. points with y_bottom <= y <= y_top and z >= z_min (head frame, mm). From true
// landmarks: y_top = forehead_top.y, y_bottom = chin_bottom.y, z_min = mean z of the two
// tragus landmarks (the coronal plane through the ears); without them, see face_region().
struct FaceRegion {
  double y_top = 0.0, y_bottom = 0.0, z_min = 0.0;
  bool contains(const Eigen::Vector3d& p) const {
    return p.y() >= y_bottom && p.y() <= y_top && p.z() >= z_min;
  }
};

// Region from true landmarks (needs forehead_top and chin_bottom; the tragi are optional,
// z_min = 0 = the head frame's ear plane without them). Throws std::invalid_argument naming a
// missing landmark or an empty height range.
FaceRegion face_region(const std::map<std::string, Eigen::Vector3d>& landmarks);

// Signed distance (mm) from each point to the nearest point of `surface`: positive outside
// (on the side its outward normals point to). Throws std::invalid_argument for a bad mesh.
std::vector<double> signed_distances(const std::vector<Eigen::Vector3d>& points,
                                     const mesh::TriMesh& surface);

struct ErrorReport {
  double mean_mm = 0.0;  // area-weighted mean |distance| of the reconstructed face surface
  double rms_mm = 0.0;
  double max_mm = 0.0;
  double diagonal_mm = 0.0;  // bounding-box diagonal of the true surface inside the region
  double relative = 0.0;     // mean_mm / diagonal_mm (seed 002 §4.1)
  int samples = 0;           // surface samples inside the region
  std::map<std::string, double> landmark_mm;  // per landmark found in both maps
  double landmark_mean_mm = 0.0;
};

// Relative error of `reconstructed` against `truth` on `region` (seed 002 §4.1): each
// reconstructed triangle whose centroid lies in the region is sampled at 7 barycentric points,
// their distances to the whole true surface are averaged with the triangle areas as weights.
// Throws std::invalid_argument for bad meshes or when no reconstructed triangle is in the region.
ErrorReport reconstruction_error(const mesh::TriMesh& reconstructed, const mesh::TriMesh& truth,
                                 const FaceRegion& region,
                                 const std::map<std::string, Eigen::Vector3d>& landmarks = {},
                                 const std::map<std::string, Eigen::Vector3d>& true_landmarks = {});

// Error colours (seed 002 fig. 4.2): negative (inside) blue, zero green, positive red,
// saturating at +-range_mm. Returns a copy of `mesh` with colors set. Throws
// std::invalid_argument when sizes differ or range_mm <= 0.
mesh::TriMesh error_colored(const mesh::TriMesh& mesh, const std::vector<double>& signed_error_mm,
                            double range_mm);

}  // namespace orthoface::model
