#include "analysis/motion_areas.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "tests/analysis/analysis_test_meshes.h"
#include "tests/common/test_data.h"

namespace orthoface::analysis {
namespace {

// Seed 001 Table I: A = (4, 5, 6), B = (1, 2, 3).
TEST(Spherical, TableOneCoordinatesAsPrinted) {
  const Spherical a = to_spherical({4, 5, 6}), b = to_spherical({1, 2, 3});
  EXPECT_NEAR(a.rho, 8.774964, 1e-6);
  EXPECT_NEAR(a.theta, 0.896055, 1e-6);
  EXPECT_NEAR(a.phi, 0.817889, 1e-6);
  EXPECT_NEAR(b.rho, 3.741657, 1e-6);
  EXPECT_NEAR(b.theta, 1.107149, 1e-6);
  EXPECT_NEAR(b.phi, 0.640522, 1e-6);
}

// Table I prints d = 9.127189 for A, B. That value cannot come from eqs. 7-9: the great-circle
// angle between the directions of A and B is acos(A.B / |A||B|) = 0.225726 rad, so d = rho_A c
// = 1.980739 (or 0.844590 with rho_B); eq. 7 taken literally (phi as latitude) gives 2.183459;
// no choice of rho (A, B, sum, mean), latitude / co-latitude or degree / radian mix reproduces
// 9.127189, which is even longer than the straight chord |A - B| = 5.196. We implement the
// consistent great-circle distance and check it against the dot-product angle.
TEST(HaversineDistance, TableOneIsTheGreatCircleArc) {
  const Spherical a = to_spherical({4, 5, 6}), b = to_spherical({1, 2, 3});
  const double angle = std::acos(32.0 / (a.rho * b.rho));
  EXPECT_NEAR(haversine_distance(a, b), a.rho * angle, 1e-9);
  EXPECT_NEAR(haversine_distance(a, b), 1.980739, 1e-6);
  EXPECT_NEAR(haversine_distance(b, a), 0.844590, 1e-6);
}

TEST(HaversineDistance, MatchesAngleEverywhereIncludingNegativeY) {
  const Eigen::Vector3d pts[] = {{1, -2, 0.5}, {-3, 1, -1}, {0, 0, 2}, {2, -0.1, -4}, {-1, -1, 1}};
  for (const auto& p : pts)
    for (const auto& q : pts) {
      const double angle = std::acos(std::clamp(p.normalized().dot(q.normalized()), -1.0, 1.0));
      EXPECT_NEAR(haversine_distance(to_spherical(p), to_spherical(q)), p.norm() * angle, 1e-9);
    }
  EXPECT_DOUBLE_EQ(to_spherical(Eigen::Vector3d::Zero()).rho, 0.0);  // degenerate: the centre
}

TEST(SegmentByFeaturePoints, SphereSplitsIntoHalvesAndSixths) {
  const mesh::TriMesh m = testing::icosphere(3, 10.0);  // 642 vertices
  const std::vector<FeaturePoint> two = {{"9.3", {0, 0, 20}}, {"11.6", {0, 0, -20}}};
  const Segmentation s = segment_by_feature_points(m, two);
  for (size_t v = 0; v < m.vertices.size(); ++v)
    if (std::abs(m.vertices[v].z()) > 1e-6) {
      EXPECT_EQ(s.label[v], m.vertices[v].z() > 0 ? 0 : 1);
    }
  EXPECT_NEAR(s.percent[0] + s.percent[1], 100.0, 1e-9);
  EXPECT_EQ(s.count[0] + s.count[1], 642);
  std::vector<FeaturePoint> six;
  const char* names[] = {"9.3", "11.6", "10.1", "10.2", "11.4", "2.1"};
  const Eigen::Vector3d dirs[] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                  {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
  for (int i = 0; i < 6; ++i) six.push_back({names[i], dirs[i] * 3.0});
  const Segmentation s6 = segment_by_feature_points(m, six);
  for (int c : s6.count) EXPECT_NEAR(c, 107, 12);  // 642 / 6, symmetric up to ties
}

TEST(SegmentByFeaturePoints, SmoothWeightsSumToOneAndPeakAtThePoint) {
  const mesh::TriMesh m = testing::icosphere(3, 50.0);
  const std::vector<FeaturePoint> pts = {{"9.3", {0, 0, 50}}, {"10.1", {50, 0, 0}}};
  SegmentationOptions o;
  o.smooth_weights = true;
  o.falloff = 30.0;
  const Segmentation s = segment_by_feature_points(m, pts, o);
  ASSERT_EQ(s.weights.size(), 2u);
  int top = 0;
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    const double sum = s.weights[0][v] + s.weights[1][v];
    if (sum > 0) {
      EXPECT_NEAR(sum, 1.0, 1e-9);
    }
    if (m.vertices[v].z() > m.vertices[top].z()) top = int(v);
  }
  EXPECT_GT(s.weights[0][top], 0.96);  // 1 / (1 + exp(-(25 pi)^2 / (2 30^2))) = 0.968
  EXPECT_GT(s.weights[0][top], s.weights[1][top]);
}

TEST(SegmentByFeaturePoints, BadInputThrows) {
  const mesh::TriMesh m = testing::icosphere(1, 1.0);
  EXPECT_THROW(segment_by_feature_points(m, {}), std::invalid_argument);
  EXPECT_THROW(segment_by_feature_points(m, {{"9.3", {0, 0, 1}}, {"9.3", {0, 1, 0}}}),
               std::invalid_argument);
  EXPECT_THROW(segment_by_feature_points(m, {{"9.3", {NAN, 0, 1}}}), std::invalid_argument);
  EXPECT_THROW(segment_by_feature_points(mesh::TriMesh{}, {{"9.3", {0, 0, 1}}}),
               std::invalid_argument);
  SegmentationOptions o;
  o.falloff = 0;
  EXPECT_THROW(segment_by_feature_points(m, {{"9.3", {0, 0, 1}}}, o), std::invalid_argument);
}

TEST(ReadFeaturePoints, FormatsAndUnknownNames) {
  const auto dir = testing::temp_dir("read_feature_points");
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const auto list = read_feature_points(
      write("a.json", R"({"feature_points": [{"name": "9.3", "position": [1, 2, 3]}]})"));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_EQ(list[0].position, Eigen::Vector3d(1, 2, 3));
  const auto map =
      read_feature_points(write("b.json", R"({"nose_tip": [0, 0, 1], "10.1": [1, 0, 0]})"));
  EXPECT_EQ(map.size(), 2u);
  const std::string bad = write("c.json", R"({"9.3": [0, 0, 1], "nose_tipp": [1, 0, 0]})");
  try {
    read_feature_points(bad);
    FAIL() << "unknown name accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nose_tipp"), std::string::npos);
  }
  EXPECT_EQ(read_feature_points(bad, true).size(), 2u);
  EXPECT_THROW(read_feature_points(write("d.json", "{not json")), std::runtime_error);
  EXPECT_THROW(read_feature_points(write("e.json", R"({"9.3": [0, 1]})")), std::runtime_error);
  EXPECT_THROW(read_feature_points(write("f.json", "{}")), std::runtime_error);
  EXPECT_THROW(read_feature_points((dir / "missing.json").string()), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::analysis
