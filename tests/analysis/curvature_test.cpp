#include "analysis/curvature.h"

#include <gtest/gtest.h>

#include <cmath>

#include "analysis/geodesics.h"
#include "tests/analysis/analysis_test_meshes.h"

namespace orthoface::analysis {
namespace {

TEST(PrincipalCurvatures, SphereIsOneOverRadius) {
  for (double r : {5.0, 80.0}) {
    const mesh::TriMesh m = testing::icosphere(3, r);
    const Curvature c = principal_curvatures(m);
    for (size_t i = 0; i < m.vertices.size(); ++i) {
      EXPECT_NEAR(c.k1[i], 1.0 / r, 0.01 / r);
      EXPECT_NEAR(c.k2[i], 1.0 / r, 0.01 / r);
      EXPECT_NEAR(c.normals[i].dot(m.vertices[i].normalized()), 1.0, 1e-6);
    }
  }
}

TEST(PrincipalCurvatures, CylinderHasOneBendingDirection) {
  const double r = 20.0;
  const mesh::TriMesh m = testing::cylinder(r, 100.0, 64, 40);
  const Curvature c = principal_curvatures(m);
  for (int row = 5; row < 35; ++row)
    for (int i = 0; i < 64; i += 7) {
      const int v = row * 64 + i;
      EXPECT_NEAR(c.k1[v], 1.0 / r, 0.03 / r);
      EXPECT_NEAR(c.k2[v], 0.0, 0.03 / r);
      EXPECT_NEAR(std::abs(c.dir2[v].y()), 1.0, 0.02);  // no bending along the axis
    }
}

TEST(PrincipalCurvatures, InsideOutSphereIsNegative) {
  mesh::TriMesh m = testing::icosphere(2, 10.0);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const Curvature c = principal_curvatures(m);
  EXPECT_NEAR(c.k1[0], -0.1, 0.002);
  EXPECT_NEAR(shape_index(c.k1[0], c.k2[0]), 1.0, 0.01);
}

TEST(PrincipalCurvatures, PlaneAndDegenerateTrianglesGiveZero) {
  mesh::TriMesh m = testing::plane_grid(6, 1.0);
  m.vertices.push_back(m.vertices[3]);
  m.triangles.push_back({3, 4, int(m.vertices.size()) - 1});  // zero area
  const Curvature c = principal_curvatures(m);
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    EXPECT_NEAR(c.k1[i], 0.0, 1e-9);
    EXPECT_NEAR(c.k2[i], 0.0, 1e-9);
  }
  EXPECT_THROW(principal_curvatures(mesh::TriMesh{}), std::invalid_argument);
}

TEST(CurvatureMetrics, KnownValues) {
  EXPECT_DOUBLE_EQ(mean_curvature(0.2, 0.1), 0.15);
  EXPECT_DOUBLE_EQ(gaussian_curvature(0.2, -0.1), -0.02);
  EXPECT_DOUBLE_EQ(shape_index(0.1, 0.1), 0.0);   // convex cap
  EXPECT_DOUBLE_EQ(shape_index(0.1, -0.1), 0.5);  // symmetric saddle
  EXPECT_DOUBLE_EQ(shape_index(0.0, 0.0), 0.5);   // plane (degenerate)
  EXPECT_DOUBLE_EQ(shape_index(0.1, 0.0), 0.25);  // ridge
  EXPECT_DOUBLE_EQ(curvedness(0.3, 0.4), std::sqrt(0.125));
  EXPECT_THROW(shape_index(0.0, 0.1), std::invalid_argument);
}

TEST(RingAverage, WeightsOneHundredTenOne) {
  const mesh::TriMesh m = testing::icosphere(1, 1.0);  // 42 vertices
  const auto nb = vertex_neighbors(m);
  std::vector<double> values(m.vertices.size(), 0.0);
  values[0] = 1.0;
  const int n1 = int(nb[0].size());
  EXPECT_NEAR(ring_average(nb, values, 0), 100.0 / (100.0 + 10.0 * n1 + 1.0 * 10), 1e-12);
  std::vector<double> ones(m.vertices.size(), 2.5);
  EXPECT_DOUBLE_EQ(ring_average(nb, ones, 5), 2.5);  // a constant stays constant
  EXPECT_THROW(ring_average(nb, values, 99), std::invalid_argument);
  EXPECT_THROW(ring_average(nb, std::vector<double>(3), 0), std::invalid_argument);
  EXPECT_THROW(ring_average(nb, values, 0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::analysis
