#pragma once

#include <string>
#include <vector>

#include "mesh/tri_mesh.h"

namespace orthoface::analysis {

// The clean mesh the analyses (features, similarity) run on, with the way back to the input.
struct AnalysisMesh {
  mesh::TriMesh mesh;                 // vertices + triangles only (no uvs / colours / texture)
  std::vector<int> original_index;    // per analysis vertex: one input vertex it came from
  std::vector<int> analysis_index;    // per input vertex: its analysis vertex, or -1 if dropped
  int welded = 0;                     // input vertices merged into another (UV seams)
  int dropped_triangles = 0;          // degenerate (zero area / repeated vertex after welding)
  int components = 0;                 // connected components of the input after welding
  std::vector<std::string> warnings;  // one line each: what was repaired or left out
};

// Welds vertices closer than weld_tolerance x bounding-box diagonal, drops degenerate triangles
// and, if keep_largest_component, every component but the largest (by triangles). Throws
// std::invalid_argument naming `what` on a malformed mesh (mesh::check_mesh: no triangles, NaN, bad
// index) or when no triangle with area is left.
AnalysisMesh analysis_mesh(const mesh::TriMesh& mesh, const std::string& what,
                           bool keep_largest_component = true, double weld_tolerance = 1e-7);

// Connected component (through shared vertices) of each vertex, 0-based, largest first; vertices
// in no triangle get -1. Throws std::invalid_argument on a malformed mesh.
std::vector<int> component_labels(const mesh::TriMesh& mesh);

}  // namespace orthoface::analysis
