#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::model {

// Vertex groups of seed 004 §5. Boundary = silhouette extremes of each slice and the centre
// line; Feature = a vertex named by a vision/landmarks.h name (a midline feature also lies on
// the centre line); NonFeature = the rest.
enum class VertexGroup { Boundary, Feature, NonFeature };

struct BaseMeshOptions {
  int vertices_per_slice = 41;  // odd, >= 9: contour points from subject right to left
  double max_slice_gap_mm = 6;  // slices are added between characteristic heights until
                                // no gap exceeds this
  // The mesh reaches beyond the face (forehead_top .. chin_bottom) by these margins, so a
  // reconstruction still covers the whole face when its top / bottom landmarks come out a few
  // mm short (new views would show background there); 0..40.
  double margin_above_mm = 15;
  double margin_below_mm = 10;
  void check() const;  // throws std::invalid_argument
};

// The generic face, front half of an average adult head in the head frame (mm, DESIGN.md),
// sliced horizontally at characteristic heights (seed 004 §5). Built from the project's own
// average head (no third-party data). Ear landmarks are not part of it.
struct BaseMesh {
  mesh::TriMesh mesh;                        // with uvs (u = contour angle, v = height)
  std::vector<VertexGroup> groups;           // one per vertex
  std::vector<int> slice_of_vertex;          // slice index per vertex
  std::vector<std::vector<int>> slices;      // per slice, top to bottom: vertex ids from the
                                             // subject's right extreme (-x) to the left (+x)
  std::vector<double> slice_heights;         // y (mm) of each slice
  std::vector<std::string> slice_names;      // "" or the landmark whose height it stands for
  std::map<std::string, int> features;       // landmark name -> vertex id
  std::vector<std::vector<int>> neighbours;  // vertex adjacency (one-ring), per vertex
  int centre(int slice) const { return slices[slice][slices[slice].size() / 2]; }
};

// Builds the base mesh (1,000–5,000 triangles with the default options). Deterministic.
// Throws std::invalid_argument when options.check() fails.
BaseMesh base_mesh(const BaseMeshOptions& options = {});

// The generic head: the point (x, z) mm of its horizontal section at height y, on the ray
// from (x 0, z 0) at `angle_rad` from +z toward +x (-pi/2 .. pi/2). Above forehead_top and
// below chin_bottom the sampled shape is extrapolated linearly (at most 40 mm, farther heights
// are clamped to that). The shape is the project's average simulated head (seed 0) sampled
// offline into model/data/generic_head.json (tools/gen_generic_head).
Eigen::Vector2d generic_contour(double y_mm, double angle_rad);

// Half-width (mm) of the generic head's front-half section at height y (ray at 90 degrees).
double generic_half_width(double y_mm);

// The generic head's landmarks (head frame, mm), names from vision/landmarks.h.
std::map<std::string, Eigen::Vector3d> generic_landmarks();

}  // namespace orthoface::model
