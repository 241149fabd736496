// The whole head and neck around the face mesh, from the two photos' silhouettes (seed 004
// slices the head: the front silhouette gives each horizontal slice's width, the side
// silhouette its front and back).
#pragma once

#include <limits>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::model {

struct HullOptions {
  double slice_mm = 2;  // vertical spacing of the slices
  int angles = 96;      // points around each slice
  // A slice is the superellipse |x/a|^n + |z/b|^n = 1 inscribed in the silhouettes' box: n =
  // front_exponent in front of the box's middle (the face's side, round), back_exponent behind
  // it (the back of a head is squarer than an ellipse).
  double front_exponent = 2, back_exponent = 2.4;
  double face_inset_mm = 3;  // where the face mesh covers the hull, the hull stays this far
                             // behind the face's nearest hollow (within hollow_mm above and
                             // below, hollow_deg around), so the face is what shows
  double hollow_mm = 10, hollow_deg = 12;
  double face_slope = 1.0;        // past the face's edge the hull rises back to its silhouette at
                                  // this many mm per mm, so it never stands in front of that edge
  double collar_widening = 1.35;  // the shoulders begin where the front silhouette is this many
                                  // times its narrowest width below the face's middle; from there
                                  // the hull keeps the last narrower slice's width
  double max_neck_mm = 70;        // and at most this far below the face mesh's lowest point
  void check() const;             // throws std::invalid_argument naming the bad field
};

// A closed head-and-neck mesh (head frame, mm, outward-facing triangles) from `front_silhouette`
// and `side_silhouette` (CV_8U, non-zero = subject; each of its camera's size in `photo_rig`,
// the rig as the photos were taken): slices from the top of the head down to the collar, each
// the superellipse inside both silhouettes' extents, pushed behind `face` (the adapted face mesh)
// wherever that covers it. Hair, ears and neck take their extent from the silhouettes; the face
// keeps the face mesh. An empty mesh (no triangles) when the silhouettes hold no head around the
// face (fewer than 8 slices). Throws std::invalid_argument naming the input when a silhouette is
// empty, not CV_8U or of another size than its camera, or the face mesh is empty.
struct HeadHull {
  mesh::TriMesh mesh;
  // Where the head turns: the neck's centre (x, z: the slices 10..40 mm below the face mesh) at
  // the height between the face's middle and its lowest point (head frame, mm). NaN without a
  // neck below the face.
  Eigen::Vector3d pivot = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};
HeadHull head_hull(const cv::Mat& front_silhouette, const cv::Mat& side_silhouette,
                   const capture::RigCalibration& photo_rig, const mesh::TriMesh& face,
                   const HullOptions& options = {});

// `a` and `b` in one mesh (b's triangles re-indexed after a's vertices). Vertex colours and uvs
// are kept only when both meshes have them (a's texture with the uvs).
mesh::TriMesh combined(const mesh::TriMesh& a, const mesh::TriMesh& b);

}  // namespace orthoface::model
