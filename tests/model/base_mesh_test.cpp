#include "model/base_mesh.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "vision/landmarks.h"

namespace orthoface::model {
namespace {

TEST(BaseMesh, TriangleCountAndGroups) {
  const BaseMesh b = base_mesh();
  mesh::check_mesh(b.mesh, "base");
  const int tris = static_cast<int>(b.mesh.triangles.size());
  EXPECT_GE(tris, 1000);
  EXPECT_LE(tris, 5000);
  ASSERT_EQ(b.groups.size(), b.mesh.vertices.size());
  ASSERT_EQ(b.mesh.uvs.size(), b.mesh.vertices.size());
  int boundary = 0, feature = 0, other = 0;
  for (VertexGroup g : b.groups)
    (g == VertexGroup::Boundary ? boundary : g == VertexGroup::Feature ? feature : other)++;
  // 3 boundary vertices per slice (2 extremes + centre), minus those that carry a feature name.
  EXPECT_EQ(feature, static_cast<int>(b.features.size()));
  EXPECT_EQ(boundary + feature + other, static_cast<int>(b.mesh.vertices.size()));
  int feature_on_boundary = 0;
  for (size_t s = 0; s < b.slices.size(); ++s)
    for (int v : {b.slices[s].front(), b.centre(static_cast<int>(s)), b.slices[s].back()})
      if (b.groups[v] == VertexGroup::Feature) ++feature_on_boundary;
  EXPECT_EQ(boundary + feature_on_boundary, 3 * static_cast<int>(b.slices.size()));
  EXPECT_EQ(b.features.size(), 26u);  // all landmarks except the four ear points
}

TEST(BaseMesh, FeaturesAreNamedLandmarksAtPlausiblePlaces) {
  const BaseMesh b = base_mesh();
  std::set<int> used;
  for (const auto& [name, v] : b.features) {
    EXPECT_TRUE(vision::is_landmark_name(name)) << name;
    EXPECT_TRUE(used.insert(v).second) << name << " shares a vertex";
    const Eigen::Vector3d p = b.mesh.vertices[v];
    if (vision::mirrored_name(name) == name) {
      EXPECT_DOUBLE_EQ(p.x(), 0.0) << name;
    }
    if (name.find("_left") != std::string::npos) {
      EXPECT_GT(p.x(), 0.0) << name;
    }
    if (name.find("_right") != std::string::npos) {
      EXPECT_LT(p.x(), 0.0) << name;
    }
  }
  const auto& v = b.mesh.vertices;
  EXPECT_GT(v[b.features.at("nose_tip")].z(), v[b.features.at("subnasale")].z() + 10);
  EXPECT_GT(v[b.features.at("nose_tip")].z(), v[b.features.at("eye_left_center")].z() + 25);
  EXPECT_GT(v[b.features.at("forehead_top")].y(), v[b.features.at("eye_left_center")].y());
  EXPECT_GT(v[b.features.at("lip_upper")].y(), v[b.features.at("lip_lower")].y());
  EXPECT_LT(v[b.features.at("chin_bottom")].y(), v[b.features.at("chin")].y());
}

// A feature vertex stands where its generic landmark is: an adaptation of the generic head to
// its own landmarks must not move anything. Off the landmark only where no slice is at its
// height (the inner and outer brow points): then along the slice at the landmark's angle.
TEST(BaseMesh, FeatureVerticesLieOnTheirGenericLandmarks) {
  const BaseMesh b = base_mesh();
  const auto generic = generic_landmarks();
  for (const auto& [name, v] : b.features) {
    const Eigen::Vector3d p = b.mesh.vertices[v], l = generic.at(name);
    // The table interpolates between rays, so the angle holds to 1e-3 rad (half a ray step
    // of the mesh, as the nearest vertex was, is 0.04 rad).
    EXPECT_NEAR(std::atan2(p.x(), p.z()), std::atan2(l.x(), l.z()), 1e-3) << name;
    if (name.find("brow") != std::string::npos && name.find("center") == std::string::npos) {
      EXPECT_LT(std::abs(p.y() - l.y()), 3.0) << name;  // the nearest slice
    } else {
      EXPECT_LT((p - l).norm(), 0.5) << name;  // the table's sampling (1 mm rows) only
    }
  }
}
TEST(BaseMesh, SlicesAreHorizontalAndOrderedRightToLeft) {
  const BaseMesh b = base_mesh();
  for (size_t s = 0; s < b.slices.size(); ++s) {
    const auto& ids = b.slices[s];
    for (size_t i = 0; i < ids.size(); ++i) {
      EXPECT_DOUBLE_EQ(b.mesh.vertices[ids[i]].y(), b.slice_heights[s]);
      if (i > 0) {
        EXPECT_GT(b.mesh.vertices[ids[i]].x(), b.mesh.vertices[ids[i - 1]].x());
      }
    }
    if (s > 0) {
      EXPECT_LT(b.slice_heights[s], b.slice_heights[s - 1]);
    }
  }
  // Outward normals: every triangle faces the front camera or the side (n.z >= 0 mostly).
  int facing = 0;
  for (const auto& f : b.mesh.triangles) {
    const Eigen::Vector3d n = (b.mesh.vertices[f[1]] - b.mesh.vertices[f[0]])
                                  .cross(b.mesh.vertices[f[2]] - b.mesh.vertices[f[0]]);
    if (n.z() > 0) ++facing;
  }
  EXPECT_GT(facing, static_cast<int>(b.mesh.triangles.size() * 0.9));
}

TEST(BaseMesh, CoarsestOptionsStillWork) {
  BaseMeshOptions o;
  o.vertices_per_slice = 9;
  o.max_slice_gap_mm = 100;
  const BaseMesh b = base_mesh(o);
  EXPECT_EQ(b.slices.size(), 14u);  // only the characteristic heights and the two margins
  mesh::check_mesh(b.mesh, "coarse base");
}

TEST(BaseMesh, BadOptionsThrow) {
  BaseMeshOptions o;
  o.vertices_per_slice = 40;
  EXPECT_THROW(base_mesh(o), std::invalid_argument);
  o.vertices_per_slice = 41;
  o.max_slice_gap_mm = 0;
  EXPECT_THROW(base_mesh(o), std::invalid_argument);
  o = {};
  o.margin_above_mm = -1;
  EXPECT_THROW(base_mesh(o), std::invalid_argument);
  o = {};
  o.margin_below_mm = 41;
  EXPECT_THROW(base_mesh(o), std::invalid_argument);
}

TEST(BaseMesh, ReachesBeyondTheFaceByTheMargins) {
  const auto l = generic_landmarks();
  const BaseMesh b = base_mesh();
  EXPECT_NEAR(b.slice_heights.front(), l.at("forehead_top").y() + 15, 1e-9);
  EXPECT_NEAR(b.slice_heights.back(), l.at("chin_bottom").y() - 10, 1e-9);
  // The named face slices keep their landmarks; the margins continue the shape smoothly:
  // above the forehead the centre recedes (smaller z) and stays within a few mm per slice.
  const Eigen::Vector3d top = b.mesh.vertices[b.centre(0)];
  const Eigen::Vector3d forehead = b.mesh.vertices[b.features.at("forehead_top")];
  EXPECT_LT(top.z(), forehead.z());
  EXPECT_GT(top.z(), forehead.z() - 15);
  EXPECT_NEAR(generic_contour(l.at("forehead_top").y(), 0).y(), forehead.z(), 0.5);
  BaseMeshOptions none;
  none.margin_above_mm = none.margin_below_mm = 0;
  const BaseMesh face_only = base_mesh(none);
  EXPECT_NEAR(face_only.slice_heights.front(), l.at("forehead_top").y(), 1e-9);
  EXPECT_NEAR(face_only.slice_heights.back(), l.at("chin_bottom").y(), 1e-9);
}

}  // namespace
}  // namespace orthoface::model
