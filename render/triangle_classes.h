#pragma once

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"

namespace orthoface::render {

// How the synthesis draws a triangle with per-pixel visibility, in element-buffer order: one
// photo's fetch alone (front, side), both photos without the occlusion test, or the full test.
enum class TriangleClass { kFrontOnly = 0, kSideOnly = 1, kUnoccluded = 2, kTested = 3 };

// A source photo as the synthesis shader samples it.
struct TriangleSource {
  capture::CameraModel camera;
  cv::Mat depth_mm;             // z_cam depth map: CV_32F of the camera's size, +inf where empty
  cv::Mat mask;                 // subject mask as the shader sees it (CV_8U 255 = subject, of the
                                // camera's size); empty = the whole photo
  bool full_resolution = true;  // the photo's texture has one texel per photo pixel
};

// What a triangle's class depends on; fixed by the mesh, the sources and the tolerance.
struct TriangleFacts {
  std::array<bool, 2> whole{};  // the source's share is exactly 1 over the triangle
  bool unoccluded = false;      // no depth map occludes it where a share can be > 0
  std::array<double, 2> lead{INFINITY, INFINITY};       // min over corners of cos_i - cos_other
  std::array<double, 2> max_cos{-INFINITY, -INFINITY};  // max over corners of cos_i
};

// The facts of each triangle (indexed like `triangles`) against the front (0) and side (1)
// sources, the occlusion test passing within visibility_tolerance_mm as in the shader. Sampled
// every half source pixel, conservatively. Throws std::invalid_argument naming the input on
// normals not sized like vertices, an index out of range, a depth map or mask of the wrong type
// or size, or a negative / non-finite tolerance.
std::vector<TriangleFacts> triangle_facts(const std::vector<Eigen::Vector3d>& vertices,
                                          const std::vector<Eigen::Vector3d>& normals,
                                          const std::vector<std::array<int, 3>>& triangles,
                                          const std::array<TriangleSource, 2>& sources,
                                          double visibility_tolerance_mm);

// The blend the classes are sorted for.
struct ClassRule {
  bool weighted = false;  // Blend::Weighted: a photo alone only where the other faces away
  double feather = 1e-6;  // Pick / View: half-width of the switch band in cos0 - cos1 (> 0)
  double bias = 0;        // View: the view bias added to cos0 - cos1 (0 for the other blends)
  // The head hull's share of the bias (SynthesisOptions::hull_view_share) and where the hull
  // begins: vertices from face_vertices on (-1: every vertex is the face).
  double hull_share = 1;
  int face_vertices = -1;
};

struct TriangleOrder {
  std::vector<std::array<int, 3>> triangles;  // grouped in TriangleClass order, mesh order within
  std::array<int, 4> count{};                 // triangles per class, indexed by TriangleClass
};

// `triangles` grouped by class under `rule`, `facts` from triangle_facts. Throws
// std::invalid_argument naming the input when facts is not sized like triangles, or the rule's
// feather is not positive and finite or its bias not finite.
TriangleOrder order_triangles(const std::vector<std::array<int, 3>>& triangles,
                              const std::vector<TriangleFacts>& facts, const ClassRule& rule);

}  // namespace orthoface::render
