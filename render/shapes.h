#pragma once

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::render {

// Closed UV ellipsoid centred at `centre` (head frame, mm) with semi-axes `radii`, cut into
// `rings` latitude bands (pole at +y) and `segments` longitudes; 2 * segments * (rings - 1)
// triangles, counter-clockwise from outside. uvs: u = longitude / 2pi measured from +z toward
// +x, v = 1 at the +y pole. With texture_px > 0 it carries a procedural texture_px square
// texture (hue bands along u, light/dark checker); else no uvs, no texture.
// Throws std::invalid_argument for rings < 2, segments < 3, radii <= 0 or texture_px > 8192.
mesh::TriMesh uv_ellipsoid(const Eigen::Vector3d& centre, const Eigen::Vector3d& radii, int rings,
                           int segments, int texture_px = 0);

// Icosphere of `radius` centred at the origin: the icosahedron with `levels` midpoint
// subdivisions (12, 42, 162, 642, 2562, 10242 ... vertices), vertices pushed onto the sphere,
// counter-clockwise from outside; no uvs. Known geodesics and curvature for the analysis tests
// and benchmarks. Throws std::invalid_argument for levels outside 0..8 or radius <= 0.
mesh::TriMesh icosphere(int levels, double radius);

}  // namespace orthoface::render
