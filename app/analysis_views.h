#pragma once
// Pictures for the mesh-analysis commands: orthographic views of a mesh with per-vertex colours
// and labelled markers.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::app {

struct Marker {
  Eigen::Vector3d position;
  std::string label;
  cv::Scalar bgr{0, 0, 255};
};

// Orthographic camera of size x size pixels looking along `view_dir` at the mesh's bounding-box
// centre, image up along `up` (made orthogonal), the whole mesh in view.
capture::CameraModel view_camera(const mesh::TriMesh& mesh, const Eigen::Vector3d& view_dir,
                                 const Eigen::Vector3d& up, int size);

// Shaded render of `mesh` (its colours, else grey) with markers on the visible side.
cv::Mat render_view(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                    const std::vector<Marker>& markers);

// Blue (0) -> green -> red (1) colour for a value in [0, 1] (clamped), RGB in [0, 1].
Eigen::Vector3d heat_rgb(double t);

// A distinct colour for label i (RGB in [0, 1]).
Eigen::Vector3d label_rgb(int i);

}  // namespace orthoface::app
