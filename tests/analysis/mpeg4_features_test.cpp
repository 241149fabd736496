#include "analysis/mpeg4_features.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include <nlohmann/json.hpp>

#include "sim/head.h"
#include "sim/scan.h"
#include "tests/analysis/analysis_test_meshes.h"
#include "tests/common/test_data.h"

namespace orthoface::analysis {
namespace {

sim::Head head16k(int seed) {
  sim::HeadOptions o;
  o.target_triangles = sim::HeadOptions::kHighTriangles;
  return sim::make_head(sim::head_params(seed), o);
}

const FoundPoint* find(const FeatureReport& r, const std::string& name) {
  for (const auto& p : r.points)
    if (p.name == name) return &p;
  return nullptr;
}

TEST(Mpeg4Features, SimHeadKeyVerticesAndMidlinePoints) {
  const sim::Head h = head16k(0);
  const FeatureReport r = mpeg4_features(h.mesh);
  ASSERT_TRUE(r.nose_tip && r.ear_left && r.ear_right) << (r.missing.empty() ? "" : r.missing[0]);
  EXPECT_LT((h.mesh.vertices[*r.nose_tip] - h.landmarks.at("nose_tip")).norm(), 5.0);
  // Ear key vertices are the dense ear clusters' centres: within 20 mm of the tragus.
  EXPECT_LT((h.mesh.vertices[*r.ear_left] - h.landmarks.at("ear_left_tragus")).norm(), 20.0);
  EXPECT_LT((h.mesh.vertices[*r.ear_right] - h.landmarks.at("ear_right_tragus")).norm(), 20.0);
  EXPECT_GT(r.axes.col(0).dot(Eigen::Vector3d::UnitX()), 0.95);  // left = subject's left
  EXPECT_GT(r.axes.col(1).dot(Eigen::Vector3d::UnitY()), 0.95);
  EXPECT_LT(std::abs(r.symmetry_plane.head<3>().dot(Eigen::Vector3d::UnitZ())), 0.1);
  const std::map<std::string, std::string> truth = {{"8.1", "lip_upper"},
                                                    {"8.2", "lip_lower"},
                                                    {"2.10", "chin"},
                                                    {"4.3", "brow_left_center"},
                                                    {"9.15", "subnasale"}};
  for (const auto& [fp, lm] : truth) {
    const FoundPoint* p = find(r, fp);
    ASSERT_NE(p, nullptr) << fp;
    EXPECT_LT((p->position - h.landmarks.at(lm)).norm(), 8.0) << fp;
  }
}

// The pupils (3.5 / 3.6) are the eyeball's bulge inside the socket, not the side plane's trough
// (the plane runs 0.25 D from the mid-plane, about 8 mm outside the eye's centre); the brows'
// uppermost points (4.3 / 4.4) are the crest above each pupil.
TEST(Mpeg4Features, SimEyeCentresOnTheEyeballsAndBrowsAboveThem) {
  for (int seed : {0, 5, 13}) {
    const sim::Head h = head16k(seed);
    const FeatureReport r = mpeg4_features(h.mesh);
    for (const auto& [fp, lm] : {std::pair<const char*, const char*>{"3.5", "eye_left_center"},
                                 {"3.6", "eye_right_center"},
                                 {"4.3", "brow_left_center"},
                                 {"4.4", "brow_right_center"}}) {
      const FoundPoint* p = find(r, fp);
      ASSERT_NE(p, nullptr) << "seed " << seed << " " << fp;
      EXPECT_LT((p->position - h.landmarks.at(lm)).norm(), 5.0) << "seed " << seed << " " << fp;
    }
  }
}

TEST(Mpeg4Features, IndependentOfPoseAndScale) {
  const sim::Head h = head16k(0);
  const FeatureReport a = mpeg4_features(h.mesh);
  mesh::TriMesh moved = h.mesh;
  const Eigen::Matrix3d rot =
      (Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, 1.0, -0.2).normalized())).toRotationMatrix();
  for (auto& v : moved.vertices) v = 0.01 * (rot * v) + Eigen::Vector3d(5, -2, 1);
  const FeatureReport b = mpeg4_features(moved);
  ASSERT_TRUE(a.nose_tip && b.nose_tip && a.ear_left && b.ear_left)
      << (b.missing.empty() ? "" : b.missing[0]);
  auto back = [&](int v) { return h.mesh.vertices[v]; };  // compare in the original frame
  EXPECT_LT((back(*a.nose_tip) - back(*b.nose_tip)).norm(), 3.0);
  EXPECT_LT((back(*a.ear_left) - back(*b.ear_left)).norm(), 3.0);
  EXPECT_LT((back(*a.ear_right) - back(*b.ear_right)).norm(), 3.0);
  for (const char* name : {"8.1", "8.2", "2.10"}) {
    const FoundPoint *pa = find(a, name), *pb = find(b, name);
    ASSERT_TRUE(pa && pb) << name;
    EXPECT_LT((back(pa->vertex) - back(pb->vertex)).norm(), 4.0) << name;
  }
}

// The Lee Perry-Smith scan (bust with shoulders, finely meshed face, eyes closed) against the
// landmarks picked on its texture and profile (sim/scan.cpp), in mm.
TEST(Mpeg4Features, LeePerrySmithScanMatchesPickedLandmarks) {
  const std::string dir = testing::shared_data("lee_perry_smith_head");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/lee_perry_smith_head";
  const sim::Head h = sim::lee_perry_smith_head(dir);
  const FeatureReport r = mpeg4_features(h.mesh);
  ASSERT_TRUE(r.nose_tip && r.ear_left) << (r.missing.empty() ? "" : r.missing[0]);
  EXPECT_LT((h.mesh.vertices[*r.nose_tip] - h.landmarks.at("nose_tip")).norm(), 6.0);
  EXPECT_GT(h.mesh.vertices[*r.ear_left].x(), 50.0);  // subject's left is +x in the head frame
  EXPECT_LT((h.mesh.vertices[*r.ear_left] - h.landmarks.at("ear_left_tragus")).norm(), 40.0);
  const std::map<std::string, std::string> truth = {
      {"8.1", "lip_upper"},      {"8.2", "lip_lower"},  {"2.10", "chin"},
      {"nasion", "nose_bridge"}, {"9.15", "subnasale"}, {"4.3", "brow_left_center"}};
  for (const auto& [fp, lm] : truth) {
    const FoundPoint* p = find(r, fp);
    ASSERT_NE(p, nullptr) << fp;
    EXPECT_LT((p->position - h.landmarks.at(lm)).norm(), 6.0) << fp;
  }
}

TEST(Mpeg4Features, FrontHalfReportsMissingEarsInsteadOfGuessing) {
  const sim::Head h = head16k(0);
  mesh::TriMesh front;
  front.vertices = h.mesh.vertices;
  for (const auto& t : h.mesh.triangles)
    if (h.mesh.vertices[t[0]].z() > 30 && h.mesh.vertices[t[1]].z() > 30 &&
        h.mesh.vertices[t[2]].z() > 30)
      front.triangles.push_back(t);
  const FeatureReport r = mpeg4_features(front);
  EXPECT_FALSE(r.ear_left.has_value());
  EXPECT_FALSE(r.nose_tip.has_value());
  EXPECT_TRUE(r.points.empty());
  ASSERT_FALSE(r.missing.empty());
  EXPECT_NE(r.missing[0].find("ears"), std::string::npos);
}

TEST(Mpeg4Features, SphereHasNoFace) {
  const FeatureReport r = mpeg4_features(testing::icosphere(4, 100.0));
  EXPECT_FALSE(r.ear_left.has_value());
  EXPECT_TRUE(r.points.empty());
  EXPECT_FALSE(r.missing.empty());
}

TEST(Mpeg4Features, BadInputThrows) {
  EXPECT_THROW(mpeg4_features(mesh::TriMesh{}), std::invalid_argument);
  mesh::TriMesh nan = testing::icosphere(1, 1.0);
  nan.vertices[3].y() = NAN;
  EXPECT_THROW(mpeg4_features(nan), std::invalid_argument);
  FeatureOptions o;
  o.neighbourhood = 0.0;
  EXPECT_THROW(mpeg4_features(testing::icosphere(1, 1.0), o), std::invalid_argument);
  o = {};
  o.ratio_threshold = 0.5;
  EXPECT_THROW(o.check(), std::invalid_argument);
  o = {};
  o.dense_area = 0.0;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

// features.json's layout (the command line and Python both use it): the key vertices at their
// mesh positions, every point, the missing list; an index outside the mesh is refused.
TEST(Mpeg4Features, ReportJsonHoldsTheReportAndRefusesForeignIndices) {
  const sim::Head h = sim::make_head(0);
  const FeatureReport r = mpeg4_features(h.mesh);
  ASSERT_TRUE(r.nose_tip.has_value());
  const nlohmann::json j = nlohmann::json::parse(feature_report_json(h.mesh, r));
  EXPECT_EQ(j["key_vertices"]["P4_nose_tip"]["vertex"], *r.nose_tip);
  EXPECT_DOUBLE_EQ(j["key_vertices"]["P4_nose_tip"]["position"][1].get<double>(),
                   h.mesh.vertices[*r.nose_tip].y());
  EXPECT_EQ(j["feature_points"].size(), r.points.size());
  EXPECT_EQ(j["missing"].size(), r.missing.size());
  EXPECT_EQ(j.contains("axes"), r.axes_found);
  const FeatureReport none = mpeg4_features(testing::icosphere(4, 100.0));
  const nlohmann::json k =
      nlohmann::json::parse(feature_report_json(testing::icosphere(4, 100.0), none));
  EXPECT_TRUE(k["key_vertices"]["P1_ear_left"].is_null());
  EXPECT_FALSE(k.contains("axes"));
  FeatureReport foreign = r;
  foreign.nose_tip = int(h.mesh.vertices.size());
  EXPECT_THROW(feature_report_json(h.mesh, foreign), std::invalid_argument);
  foreign = r;
  ASSERT_FALSE(foreign.points.empty());
  foreign.points[0].vertex = -1;
  EXPECT_THROW(feature_report_json(h.mesh, foreign), std::invalid_argument);
}

TEST(GeodesicEuclideanRatio, FoldIsHighPlaneIsOne) {
  // A plane has ratio 1; a thin fold (two close sheets joined at one edge) is high.
  const mesh::TriMesh flat = testing::plane_grid(20, 1.0);
  for (double q : geodesic_euclidean_ratio(flat)) EXPECT_NEAR(q, 1.0, 1e-9);
  mesh::TriMesh fold = testing::plane_grid(20, 1.0);
  const int n = int(fold.vertices.size());
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d v = fold.vertices[i];
    fold.vertices.push_back({v.x(), v.y(), 0.0});
  }
  // Second sheet: mirror of the first in x about x = 0 then lifted: an accordion fold.
  for (int i = 0; i < n; ++i)
    fold.vertices[n + i] = {-fold.vertices[i].x(), fold.vertices[i].y(), 0.6};
  for (int i = 0; i < n; ++i)
    if (fold.vertices[i].x() == 0.0) fold.vertices[n + i] = fold.vertices[i];
  const size_t t0 = fold.triangles.size();
  for (size_t t = 0; t < t0; ++t) {
    const auto& f = fold.triangles[t];
    fold.triangles.push_back({f[0] + n, f[2] + n, f[1] + n});
  }
  const auto r = geodesic_euclidean_ratio(fold);
  EXPECT_GT(*std::max_element(r.begin(), r.end()), 3.0);
  EXPECT_THROW(geodesic_euclidean_ratio(mesh::TriMesh{}), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::analysis
