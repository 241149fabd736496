#pragma once

#include <vector>

#include "mesh/tri_mesh.h"

namespace orthoface::mesh {

struct TopologyOptions {
  double weld_tolerance = 1e-6;  // vertices closer than this * bounding-box diagonal are one
  void check() const;            // throws std::invalid_argument if negative or not finite
};

// Connectivity of a triangle mesh after welding coincident vertices (UV seams split vertices,
// so topology is judged on positions). Counts refer to the welded mesh.
struct TopologyReport {
  int input_vertices = 0;
  int vertices = 0;           // welded vertices used by a valid triangle
  int isolated_vertices = 0;  // welded vertices used by no valid triangle
  int edges = 0;
  int triangles = 0;              // valid (non-degenerate) triangles
  int degenerate_triangles = 0;   // a repeated welded vertex or (near) zero area
  int boundary_edges = 0;         // edges with one triangle
  int non_manifold_edges = 0;     // edges with more than two triangles
  int non_manifold_vertices = 0;  // vertices whose triangles form more than one fan
  int inconsistent_edges = 0;     // two-triangle edges used in the same direction by both
  int components = 0;             // triangle sets connected through shared vertices
  int euler_characteristic = 0;   // vertices - edges + triangles
  bool closed() const { return boundary_edges == 0; }
  bool manifold() const { return non_manifold_edges == 0 && non_manifold_vertices == 0; }
  // Closed, manifold, consistently oriented, one component, no degenerate triangles.
  bool watertight() const {
    return closed() && manifold() && inconsistent_edges == 0 && components == 1 &&
           degenerate_triangles == 0;
  }
};

// For each vertex, the index of its welded representative (the lowest index among the vertices
// within tolerance * bounding-box diagonal; transitive). Throws std::invalid_argument on a
// non-finite vertex or bad options.
std::vector<int> weld_map(const TriMesh& mesh, const TopologyOptions& options = {});

// The mesh with coincident vertices merged (attributes of the representative kept) and the
// triangles that collapse dropped. Throws std::invalid_argument as check_mesh does.
TriMesh weld(const TriMesh& mesh, const TopologyOptions& options = {});

// Topology of `mesh` (see TopologyReport). Throws std::invalid_argument when check_mesh fails.
TopologyReport topology_report(const TriMesh& mesh, const TopologyOptions& options = {});

}  // namespace orthoface::mesh
