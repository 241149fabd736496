#include "sim/scan.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

#include "mesh/mesh_io.h"
#include "mesh/topology.h"
#include "tests/common/test_data.h"
#include "tests/sim/mesh_distance.h"
#include "vision/landmarks.h"

namespace orthoface::sim {
namespace {

TEST(LoadScan, SimHeadAsObjGivesItsOwnProfileLandmarksAndScale) {
  const auto dir = testing::temp_dir("scan_sim_obj");
  HeadOptions o;
  o.texture_size = 256;
  o.target_triangles = HeadOptions::kHighTriangles;
  const Head truth = make_head(head_params(0), o);
  mesh::TriMesh scaled = truth.mesh;
  for (auto& v : scaled.vertices) v /= 100.0;  // a scan in decimetres
  mesh::write_mesh(scaled, (dir / "head.obj").string());
  ScanOptions so;
  so.head_width_mm = HeadParams{}.head_width;
  const Head scan = load_scan((dir / "head.obj").string(), so);
  EXPECT_FALSE(scan.mesh.texture.empty());
  // Scale estimated from the skull breadth: the nose-to-chin distance comes out within 3 %.
  const double truth_len = (truth.landmarks.at("nose_tip") - truth.landmarks.at("chin")).norm();
  const double scan_len = (scan.landmarks.at("nose_tip") - scan.landmarks.at("chin")).norm();
  EXPECT_NEAR(scan_len / truth_len, 1.0, 0.03);
  // With the exact scale, the profile landmarks match the truth up to the origin estimate.
  so.mm_per_unit = 100;
  const Head exact = load_scan((dir / "head.obj").string(), so);
  const Eigen::Vector3d shift = truth.landmarks.at("nose_tip") - exact.landmarks.at("nose_tip");
  for (const char* name : {"nose_bridge", "subnasale", "lip_upper", "lip_lower", "chin"})
    EXPECT_LT((exact.landmarks.at(name) + shift - truth.landmarks.at(name)).norm(), 2.0) << name;
  EXPECT_LT(shift.norm(), 15.0);  // origin estimate (125 mm below the top, mid-section)
}

TEST(LoadScan, RejectsBadInput) {
  EXPECT_THROW(load_scan("/nonexistent/head.obj"), std::runtime_error);
  EXPECT_THROW(lee_perry_smith_head("/nonexistent"), std::runtime_error);
  ScanOptions o;
  o.mm_per_unit = -1;
  EXPECT_THROW(load_scan("/nonexistent/head.obj", o), std::invalid_argument);
  o = ScanOptions{};
  o.head_width_mm = std::nan("");
  EXPECT_THROW(o.check(), std::invalid_argument);
}

TEST(ScanProfileLandmarks, NeedsAMeshCrossingTheMidline) {
  mesh::TriMesh m;
  m.vertices = {{10, 0, 0}, {11, 0, 0}, {10, 1, 0}};
  m.triangles = {{0, 1, 2}};
  EXPECT_THROW(scan_profile_landmarks(m), std::runtime_error);
}

TEST(PointAtUv, FindsVerticesAndRejectsMissingUvs) {
  HeadOptions o;
  o.texture_size = 64;
  const Head h = make_head(head_params(1), o);
  for (int i : {100, 700, 1500}) {
    const auto p = point_at_uv(h.mesh, h.mesh.uvs[i]);
    ASSERT_TRUE(p.has_value());
    EXPECT_LT((*p - h.mesh.vertices[i]).norm(), 1e-6);
  }
  EXPECT_FALSE(point_at_uv(h.mesh, Eigen::Vector2d(1.5, 0.5)).has_value());
  mesh::TriMesh bare = h.mesh;
  bare.uvs.clear();
  EXPECT_THROW(point_at_uv(bare, Eigen::Vector2d(0.5, 0.5)), std::invalid_argument);
}

TEST(LeePerrySmith, LoadsInTheHeadFrameWithAllLandmarks) {
  const std::string dir = testing::shared_data("lee_perry_smith_head");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/lee_perry_smith_head";
  const Head h = lee_perry_smith_head(dir);
  EXPECT_TRUE(h.landmarks_picked);
  EXPECT_EQ(h.mesh.texture.rows, 1024);
  const mesh::TopologyReport r = mesh::topology_report(h.mesh);
  EXPECT_TRUE(r.watertight());
  EXPECT_EQ(r.euler_characteristic, 2);
  for (const auto name : vision::kLandmarkNames) {
    ASSERT_TRUE(h.landmarks.count(std::string(name))) << name;
    EXPECT_LT(distance_to_mesh(h.mesh, h.landmarks.at(std::string(name))), 0.5) << name;
  }
  const auto& l = h.landmarks;
  // Origin between the tragi; subject's left is +x; face toward +z; human proportions.
  EXPECT_NEAR(l.at("ear_left_tragus").y() + l.at("ear_right_tragus").y(), 0, 1e-9);
  EXPECT_GT(l.at("eye_left_center").x(), 20);
  EXPECT_LT(l.at("eye_right_center").x(), -20);
  EXPECT_GT(l.at("nose_tip").z(), 80);
  const double eye_distance = (l.at("eye_left_center") - l.at("eye_right_center")).norm();
  EXPECT_NEAR(eye_distance, 64, 8);
  const double face_height = l.at("forehead_top").y() - l.at("chin_bottom").y();
  EXPECT_GT(face_height, 140);
  EXPECT_LT(face_height, 210);
  double zmax = -1e9;
  for (const auto& v : h.mesh.vertices)
    if (std::abs(v.x()) < 10) zmax = std::max(zmax, v.z());
  EXPECT_NEAR(l.at("nose_tip").z(), zmax, 0.5);
}

}  // namespace
}  // namespace orthoface::sim
