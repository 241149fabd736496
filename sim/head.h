#pragma once

#include <map>
#include <string>

#include <Eigen/Core>

#include "model/tri_mesh.h"

namespace orthoface::sim {

// A head with known ground truth: textured, closed, manifold mesh in the head frame (mm,
// DESIGN.md) and 3D landmarks named as in vision/landmarks.h.
struct Head {
  model::TriMesh mesh;
  std::map<std::string, Eigen::Vector3d> landmarks;
  std::string name;  // "sim seed N", "Lee Perry-Smith scan", ...
};

}  // namespace orthoface::sim
