#pragma once

// The generic head shape behind base_mesh() (not public API): model/data/generic_head.json,
// written by tools/gen_generic_head from the average simulated head and embedded into the
// library at build time, so model/ neither links sim/ nor reads a file at run time.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace orthoface::model::detail {

struct GenericHead {
  int rows = 0, half_rays = 0;  // contour table: rows top to bottom, rays 0..90 degrees
  double top = 0, bottom = 0;   // heights (mm) of the first and last row
  std::vector<std::array<double, 2>> contour;  // rows * half_rays (x, z), row-major
  std::vector<std::pair<std::string, Eigen::Vector3d>> landmarks;
  const std::array<double, 2>& at(int row, int ray) const {
    return contour[size_t(row) * half_rays + ray];
  }
};

// Parsed once from the embedded JSON. Throws std::logic_error when the embedded data is
// malformed (a build defect, caught by the model tests).
const GenericHead& generic_head();

// The embedded JSON text (generated at build time from model/data/generic_head.json).
extern const char* const kGenericHeadJson;

}  // namespace orthoface::model::detail
