#include "mesh/topology.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace orthoface::mesh {
namespace {

// Outward-oriented tetrahedron.
TriMesh tetrahedron(const Eigen::Vector3d& offset = Eigen::Vector3d::Zero()) {
  TriMesh m;
  m.vertices = {offset + Eigen::Vector3d(0, 0, 0), offset + Eigen::Vector3d(1, 0, 0),
                offset + Eigen::Vector3d(0, 1, 0), offset + Eigen::Vector3d(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

// Tetrahedron whose faces each have their own three vertices (like a mesh split at UV seams).
TriMesh split_tetrahedron() {
  const TriMesh t = tetrahedron();
  TriMesh m;
  for (const auto& f : t.triangles) {
    const int base = static_cast<int>(m.vertices.size());
    for (int k = 0; k < 3; ++k) m.vertices.push_back(t.vertices[f[k]]);
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

TEST(TopologyReport, ClosedTetrahedronIsWatertightSphere) {
  const TopologyReport r = topology_report(tetrahedron());
  EXPECT_EQ(r.vertices, 4);
  EXPECT_EQ(r.edges, 6);
  EXPECT_EQ(r.triangles, 4);
  EXPECT_EQ(r.euler_characteristic, 2);
  EXPECT_EQ(r.components, 1);
  EXPECT_TRUE(r.closed());
  EXPECT_TRUE(r.manifold());
  EXPECT_TRUE(r.watertight());
}

TEST(TopologyReport, WeldsSplitVerticesBeforeJudging) {
  const TriMesh m = split_tetrahedron();
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.input_vertices, 12);
  EXPECT_EQ(r.vertices, 4);
  EXPECT_TRUE(r.watertight());
  // Without welding (tolerance 0 still merges identical positions) the same holds.
  EXPECT_TRUE(topology_report(m, {0.0}).watertight());
}

TEST(TopologyReport, OpenMeshHasBoundaryEdges) {
  TriMesh m = tetrahedron();
  m.triangles.pop_back();
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.boundary_edges, 3);
  EXPECT_FALSE(r.closed());
  EXPECT_TRUE(r.manifold());
  EXPECT_EQ(r.euler_characteristic, 1);  // a disc
}

TEST(TopologyReport, CountsComponents) {
  TriMesh m = tetrahedron();
  const TriMesh b = tetrahedron(Eigen::Vector3d(5, 0, 0));
  for (const auto& f : b.triangles) m.triangles.push_back({f[0] + 4, f[1] + 4, f[2] + 4});
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.euler_characteristic, 4);
  EXPECT_FALSE(r.watertight());
}

TEST(TopologyReport, FindsNonManifoldEdgeAndVertex) {
  TriMesh fin;  // three triangles on one edge
  fin.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  EXPECT_EQ(topology_report(fin).non_manifold_edges, 1);
  TriMesh bowtie;  // two triangles touching at one vertex
  bowtie.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
  const TopologyReport r = topology_report(bowtie);
  EXPECT_EQ(r.non_manifold_vertices, 1);
  EXPECT_EQ(r.non_manifold_edges, 0);
  EXPECT_FALSE(r.manifold());
}

TEST(TopologyReport, FindsDegenerateAndFlippedTriangles) {
  TriMesh m = tetrahedron();
  m.vertices.push_back({2, 0, 0});  // collinear with 0 and 1
  m.triangles.push_back({0, 1, 4});
  EXPECT_EQ(topology_report(m).degenerate_triangles, 1);
  TriMesh flipped = tetrahedron();
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_EQ(topology_report(flipped).inconsistent_edges, 3);
}

TEST(TopologyReport, IsolatedVertexIsCounted) {
  TriMesh m = tetrahedron();
  m.vertices.push_back({9, 9, 9});
  const TopologyReport r = topology_report(m);
  EXPECT_EQ(r.isolated_vertices, 1);
  EXPECT_EQ(r.vertices, 4);
}

TEST(TopologyReport, RejectsBadInput) {
  TriMesh m = tetrahedron();
  m.vertices[1].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(topology_report(m), std::invalid_argument);
  EXPECT_THROW(topology_report(TriMesh{}), std::invalid_argument);
  EXPECT_THROW(topology_report(tetrahedron(), {-1.0}), std::invalid_argument);
}

TEST(Weld, MergesWithinToleranceOnly) {
  TriMesh m = split_tetrahedron();
  m.vertices[0] += Eigen::Vector3d(1e-9, 0, 0);
  EXPECT_EQ(weld(m).vertices.size(), 4u);
  m.vertices[0] += Eigen::Vector3d(0.01, 0, 0);  // far beyond 1e-6 * diagonal
  EXPECT_EQ(weld(m).vertices.size(), 5u);
  const std::vector<int> rep = weld_map(split_tetrahedron());
  EXPECT_EQ(rep[0], 0);
  for (size_t i = 0; i < rep.size(); ++i) EXPECT_LE(rep[i], static_cast<int>(i));
}

TEST(Weld, EmptyVertexListGivesEmptyMap) { EXPECT_TRUE(weld_map(TriMesh{}).empty()); }

TEST(Weld, DropsCollapsedTrianglesAndKeepsAttributes) {
  TriMesh m = tetrahedron();
  m.vertices.push_back(m.vertices[0]);  // duplicate of vertex 0
  m.triangles.push_back({0, 4, 1});     // collapses after welding
  m.uvs.assign(5, Eigen::Vector2d(0.5, 0.25));
  const TriMesh w = weld(m);
  EXPECT_EQ(w.vertices.size(), 4u);
  EXPECT_EQ(w.triangles.size(), 4u);
  ASSERT_EQ(w.uvs.size(), 4u);
  EXPECT_DOUBLE_EQ(w.uvs[0].y(), 0.25);
  EXPECT_THROW(weld(TriMesh{}), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::mesh
