#include "model/evaluate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "model/base_mesh.h"

namespace orthoface::model {
namespace {

FaceRegion whole_base_region() { return {100.0, -100.0, -1000.0}; }

TEST(ReconstructionError, SelfIsZeroAndOffsetIsOffsetOverDiagonal) {
  const BaseMesh b = base_mesh();
  const ErrorReport self = reconstruction_error(b.mesh, b.mesh, whole_base_region());
  EXPECT_NEAR(self.mean_mm, 0.0, 1e-9);
  EXPECT_NEAR(self.relative, 0.0, 1e-12);
  // A plane 2 mm in front of a plane: every sample is 2 mm away.
  mesh::TriMesh plane;
  plane.vertices = {{-50, -50, 0}, {50, -50, 0}, {50, 50, 0}, {-50, 50, 0}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  mesh::TriMesh shifted = plane;
  for (auto& v : shifted.vertices) v.z() += 2.0;
  const ErrorReport e = reconstruction_error(shifted, plane, {60, -60, -10});
  EXPECT_NEAR(e.mean_mm, 2.0, 1e-9);
  EXPECT_NEAR(e.diagonal_mm, std::sqrt(2.0) * 100.0, 1e-9);
  EXPECT_NEAR(e.relative, 2.0 / (std::sqrt(2.0) * 100.0), 1e-12);
}

TEST(ReconstructionError, LandmarkErrors) {
  const BaseMesh b = base_mesh();
  const ErrorReport e = reconstruction_error(
      b.mesh, b.mesh, whole_base_region(), {{"nose_tip", {0, 0, 3}}, {"chin", {0, 0, 0}}},
      {{"nose_tip", {0, 4, 0}}, {"eye_left_center", {0, 0, 0}}});
  ASSERT_EQ(e.landmark_mm.size(), 1u);
  EXPECT_NEAR(e.landmark_mm.at("nose_tip"), 5.0, 1e-12);
  EXPECT_NEAR(e.landmark_mean_mm, 5.0, 1e-12);
}

TEST(ReconstructionError, EmptyRegionAndBadMeshThrow) {
  const BaseMesh b = base_mesh();
  EXPECT_THROW(reconstruction_error(b.mesh, b.mesh, {500, 400, 0}), std::invalid_argument);
  mesh::TriMesh empty;
  EXPECT_THROW(reconstruction_error(empty, b.mesh, whole_base_region()), std::invalid_argument);
}

TEST(SignedDistances, SignFollowsNormalsAndFarPointsWork) {
  mesh::TriMesh plane;  // 100 x 100 mm square in z = 0, normal +z, split in 8 x 8 cells
  for (int r = 0; r <= 8; ++r)
    for (int c = 0; c <= 8; ++c) plane.vertices.emplace_back(-50 + 12.5 * c, -50 + 12.5 * r, 0);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c) {
      const int a = r * 9 + c;
      plane.triangles.push_back({a, a + 1, a + 10});
      plane.triangles.push_back({a, a + 10, a + 9});
    }
  const auto d = signed_distances({{3, 7, 4}, {-20, 10, -3}, {500, 0, 0}, {50, 50, 0}}, plane);
  EXPECT_NEAR(d[0], 4.0, 1e-9);
  EXPECT_NEAR(d[1], -3.0, 1e-9);
  EXPECT_NEAR(std::abs(d[2]), 450.0, 1e-9);  // far outside the grid
  EXPECT_NEAR(d[3], 0.0, 1e-9);              // on a corner
  EXPECT_THROW(signed_distances({{0, 0, 0}}, mesh::TriMesh{}), std::invalid_argument);
}

// Two 1 mm triangles a kilometre apart (a valid file that made `eval` run for hours: the grid's
// cells followed the tiny edges): distances stay exact, near and far, and come back at once.
TEST(SignedDistances, SparseFarApartGeometryStaysExactAndBounded) {
  mesh::TriMesh far;
  far.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1e6, 0, 0}, {1e6 + 1, 0, 0}, {1e6, 1, 0}};
  far.triangles = {{0, 1, 2}, {3, 4, 5}};
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 2000; ++i)
    points.emplace_back(i * 500.0 + 0.25, 0.25 * (i % 3), 5.0 * ((i % 7) - 3));
  points.emplace_back(-3e9, 2e9, 7e8);  // far outside everything
  const auto d = signed_distances(points, far);
  ASSERT_EQ(d.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    // The nearest point of either triangle, by brute force.
    double truth = std::numeric_limits<double>::infinity();
    for (const double x0 : {0.0, 1e6}) {
      const double u = std::clamp(p.x() - x0, 0.0, 1.0), v = std::clamp(p.y(), 0.0, 1.0 - u);
      const double w = std::clamp(p.x() - x0, 0.0, 1.0 - v);
      truth = std::min(truth, (p - Eigen::Vector3d(x0 + w, v, 0)).norm());
    }
    EXPECT_NEAR(std::abs(d[i]), truth, 1e-6 * (1 + truth)) << i;
  }
}

TEST(FaceRegion, FromLandmarks) {
  const FaceRegion r = face_region({{"forehead_top", {0, 80, 90}},
                                    {"chin_bottom", {0, -80, 80}},
                                    {"ear_left_tragus", {70, 0, 2}},
                                    {"ear_right_tragus", {-70, 0, -4}}});
  EXPECT_DOUBLE_EQ(r.y_top, 80);
  EXPECT_DOUBLE_EQ(r.y_bottom, -80);
  EXPECT_DOUBLE_EQ(r.z_min, -1);
  EXPECT_TRUE(r.contains({0, 0, 0}));
  EXPECT_FALSE(r.contains({0, 0, -2}));
  EXPECT_THROW(face_region({{"forehead_top", {0, 80, 90}}}), std::invalid_argument);
  EXPECT_THROW(face_region({{"forehead_top", {0, -90, 90}}, {"chin_bottom", {0, -80, 80}}}),
               std::invalid_argument);
}

TEST(ErrorColored, BlueGreenRed) {
  const BaseMesh b = base_mesh();
  std::vector<double> err(b.mesh.vertices.size(), 0.0);
  err[0] = -5, err[1] = 5, err[2] = 1;
  const mesh::TriMesh c = error_colored(b.mesh, err, 2.0);
  EXPECT_EQ(c.colors[0], Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(c.colors[1], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(c.colors[2], Eigen::Vector3d(0.5, 0.5, 0));
  EXPECT_EQ(c.colors[3], Eigen::Vector3d(0, 1, 0));
  EXPECT_THROW(error_colored(b.mesh, {1.0}, 2.0), std::invalid_argument);
  EXPECT_THROW(error_colored(b.mesh, err, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::model
