// Triangle classes of the synthesis' fast paths on a tiny ideal rig (64 x 48, 1 px/mm): the
// front camera looks along -z, the side camera along -x, both from 1000 mm.
#include "render/triangle_classes.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace orthoface::render {
namespace {

using Triangles = std::vector<std::array<int, 3>>;

struct Scene {
  std::vector<Eigen::Vector3d> vertices, normals;
  Triangles triangles;
  std::array<TriangleSource, 2> sources;
};

// Depth maps of the plane n . p = 0 (+inf where a camera sees it edge-on), with a wall at
// z_cam = `front_wall_mm` in front of the front camera's whole view when that is nearer.
std::array<TriangleSource, 2> sources(const Eigen::Vector3d& n, double front_wall_mm) {
  const capture::RigCalibration rig = capture::ideal_rig(64, 48, 1.0);
  std::array<TriangleSource, 2> s;
  s[0].camera = rig.front;
  s[1].camera = rig.side;
  for (TriangleSource& source : s) source.depth_mm.create(48, 64, CV_32F);
  for (int r = 0; r < 48; ++r)
    for (int c = 0; c < 64; ++c) {
      // Pixel centre in camera coordinates: x_cam right, y_cam down (1 mm per pixel).
      const double x_cam = c + 0.5 - 32, y_cam = r + 0.5 - 24;
      // Front: head (x, y) = (x_cam, -y_cam), z_cam = 1000 - z. Side: head (y, z) = (-y_cam,
      // -x_cam), z_cam = 1000 - x.
      const double z = n.z() == 0 ? -INFINITY : -(n.x() * x_cam - n.y() * y_cam) / n.z();
      const double x = n.x() == 0 ? -INFINITY : -(-n.y() * y_cam - n.z() * x_cam) / n.x();
      s[0].depth_mm.at<float>(r, c) = float(std::min(1000 - z, front_wall_mm));
      s[1].depth_mm.at<float>(r, c) = float(1000 - x);
    }
  return s;
}

// One triangle about the origin with unit normal n (corners on the plane through 0 normal to n).
Scene one_triangle(const Eigen::Vector3d& n, double front_wall_mm = INFINITY) {
  const Eigen::Vector3d u = n.cross(Eigen::Vector3d::UnitY()).normalized(), v = n.cross(u);
  Scene s;
  s.vertices = {-5 * u - 5 * v, 5 * u - 5 * v, 5 * v};
  s.normals.assign(3, n.normalized());
  s.triangles = {{0, 1, 2}};
  s.sources = sources(n.normalized(), front_wall_mm);
  return s;
}

TriangleFacts facts_of(const Scene& s) {
  const auto facts = triangle_facts(s.vertices, s.normals, s.triangles, s.sources, 1.0);
  EXPECT_EQ(facts.size(), 1u);
  return facts.at(0);
}

TriangleClass class_of(const TriangleFacts& f, const ClassRule& rule = {false, 0.1, 0}) {
  const TriangleOrder order = order_triangles({{0, 1, 2}}, {f}, rule);
  for (int k = 0; k < 4; ++k)
    if (order.count[k] == 1) return TriangleClass(k);
  ADD_FAILURE() << "no class";
  return TriangleClass::kTested;
}

TEST(TriangleFacts, FacingTheFrontCameraOnlyIsFrontOnly) {
  const TriangleFacts f = facts_of(one_triangle(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(f.whole[0]);
  EXPECT_FALSE(f.whole[1]);  // seen edge-on by the side camera: its share is 0
  EXPECT_TRUE(f.unoccluded);
  EXPECT_NEAR(f.lead[0], 1, 1e-12);
  EXPECT_NEAR(f.max_cos[1], 0, 1e-12);
  EXPECT_EQ(class_of(f), TriangleClass::kFrontOnly);
  // Weighted: a photo alone only where the other faces away (edge-on is cos 6e-17 > 0 here).
  EXPECT_EQ(class_of(f, {true, 0.1, 0}), TriangleClass::kUnoccluded);
  const TriangleFacts away = facts_of(one_triangle(Eigen::Vector3d(-0.1, 0, 1).normalized()));
  EXPECT_EQ(class_of(away, {true, 0.1, 0}), TriangleClass::kFrontOnly);
}

TEST(TriangleFacts, FacingTheSideCameraOnlyIsSideOnly) {
  const TriangleFacts f = facts_of(one_triangle(Eigen::Vector3d::UnitX()));
  EXPECT_FALSE(f.whole[0]);
  EXPECT_TRUE(f.whole[1]);
  EXPECT_EQ(class_of(f), TriangleClass::kSideOnly);
}

// At 45 degrees both photos cover the triangle wholly and neither leads: both are blended, with
// no occlusion test, unless the view bias hands it to one of them.
TEST(TriangleFacts, FacingBothCamerasIsUnoccludedUnlessTheBiasDecides) {
  const TriangleFacts f = facts_of(one_triangle(Eigen::Vector3d(1, 0, 1).normalized()));
  EXPECT_TRUE(f.whole[0] && f.whole[1] && f.unoccluded);
  EXPECT_NEAR(f.lead[0], 0, 1e-12);
  EXPECT_NEAR(f.max_cos[0], std::sqrt(0.5), 1e-12);
  EXPECT_EQ(class_of(f), TriangleClass::kUnoccluded);
  EXPECT_EQ(class_of(f, {false, 0.1, 0.5}), TriangleClass::kFrontOnly);
  EXPECT_EQ(class_of(f, {false, 0.1, -0.5}), TriangleClass::kSideOnly);
  EXPECT_EQ(class_of(f, {true, 0.1, 0.5}), TriangleClass::kUnoccluded);  // weighted: both seen
}

// The head hull keeps only its share of the view bias: a hull triangle the face's bias would hand
// to the front photo is blended; one spanning face and hull must hold under both biases.
TEST(TriangleFacts, TheHullsTrianglesAreClassedByTheHullsShareOfTheBias) {
  const TriangleFacts f = facts_of(one_triangle(Eigen::Vector3d(1, 0, 1).normalized()));
  EXPECT_EQ(class_of(f, {false, 0.1, 0.5, 0.0, 3}), TriangleClass::kFrontOnly);   // all face
  EXPECT_EQ(class_of(f, {false, 0.1, 0.5, 0.0, 0}), TriangleClass::kUnoccluded);  // all hull
  EXPECT_EQ(class_of(f, {false, 0.1, 0.5, 0.0, 1}), TriangleClass::kUnoccluded);  // both
  EXPECT_EQ(class_of(f, {false, 0.1, 0.5, 0.5, 0}), TriangleClass::kFrontOnly);   // 0.25 >= 0.1
  EXPECT_EQ(class_of(f, {false, 0.1, -0.5, 0.1, 0}), TriangleClass::kUnoccluded);
  EXPECT_THROW(order_triangles({{0, 1, 2}}, {f}, {false, 0.1, 0.5, 1.5, 0}), std::invalid_argument);
}

TEST(TriangleFacts, HiddenBehindAnotherSurfaceInOneSourceIsTested) {
  const TriangleFacts f = facts_of(one_triangle(Eigen::Vector3d::UnitZ(), 900));
  EXPECT_FALSE(f.whole[0]);
  EXPECT_FALSE(f.unoccluded);
  EXPECT_EQ(class_of(f), TriangleClass::kTested);
}

// Outside the subject mask, or in a downscaled texture, a photo's share is not provably 1.
TEST(TriangleFacts, MaskedOrDownscaledPhotoIsNotWhole) {
  Scene s = one_triangle(Eigen::Vector3d::UnitZ());
  s.sources[0].mask = cv::Mat::zeros(48, 64, CV_8U);
  TriangleFacts f = facts_of(s);
  EXPECT_FALSE(f.whole[0]);
  EXPECT_TRUE(f.unoccluded);
  EXPECT_EQ(class_of(f), TriangleClass::kUnoccluded);
  s.sources[0].mask = cv::Mat(48, 64, CV_8U, cv::Scalar(255));
  EXPECT_TRUE(facts_of(s).whole[0]);
  s.sources[0].full_resolution = false;
  EXPECT_FALSE(facts_of(s).whole[0]);
}

TEST(TriangleFacts, NoTrianglesGiveNoFacts) {
  const Scene s = one_triangle(Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(triangle_facts(s.vertices, s.normals, {}, s.sources, 1.0).empty());
}

TEST(TriangleFacts, RefusesBadInputNamingIt) {
  const Scene s = one_triangle(Eigen::Vector3d::UnitZ());
  auto message = [](const auto& call) -> std::string {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  };
  auto facts = [&](const Scene& bad, double tolerance = 1.0) {
    return message(
        [&] { triangle_facts(bad.vertices, bad.normals, bad.triangles, bad.sources, tolerance); });
  };
  Scene bad = s;
  bad.normals.pop_back();
  EXPECT_NE(facts(bad).find("normals"), std::string::npos) << facts(bad);
  bad = s;
  bad.triangles = {{0, 1, 3}};
  EXPECT_NE(facts(bad).find("triangles"), std::string::npos) << facts(bad);
  bad = s;
  bad.sources[1].depth_mm = cv::Mat(10, 10, CV_32F);
  EXPECT_NE(facts(bad).find("side source depth_mm"), std::string::npos) << facts(bad);
  bad = s;
  bad.sources[0].depth_mm.convertTo(bad.sources[0].depth_mm, CV_64F);
  EXPECT_NE(facts(bad).find("front source depth_mm"), std::string::npos) << facts(bad);
  bad = s;
  bad.sources[0].mask = cv::Mat(48, 64, CV_8UC3);
  EXPECT_NE(facts(bad).find("front source mask"), std::string::npos) << facts(bad);
  EXPECT_NE(facts(s, -1).find("visibility_tolerance_mm"), std::string::npos);
  EXPECT_NE(facts(s, NAN).find("visibility_tolerance_mm"), std::string::npos);
}

// Classes come out grouped in TriangleClass order, each in mesh order, counted.
TEST(OrderTriangles, GroupsClassesInOrder) {
  TriangleFacts front_only, side_only, unoccluded, tested;
  front_only.whole = {true, false}, front_only.unoccluded = true, front_only.lead = {1, -1};
  side_only.whole = {false, true}, side_only.unoccluded = true, side_only.lead = {-1, 1};
  unoccluded.whole = {true, true}, unoccluded.unoccluded = true, unoccluded.lead = {0, 0};
  tested.whole = {false, false}, tested.unoccluded = false, tested.lead = {0, 0};
  const Triangles triangles = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {4, 4, 4}, {5, 5, 5}};
  const std::vector<TriangleFacts> facts = {tested,     side_only,  front_only,
                                            unoccluded, front_only, tested};
  const TriangleOrder order = order_triangles(triangles, facts, {false, 0.1, 0});
  EXPECT_EQ(order.count, (std::array<int, 4>{2, 1, 1, 2}));
  EXPECT_EQ(order.triangles,
            (Triangles{{2, 2, 2}, {4, 4, 4}, {1, 1, 1}, {3, 3, 3}, {0, 0, 0}, {5, 5, 5}}));
  const TriangleOrder none = order_triangles({}, {}, {});
  EXPECT_TRUE(none.triangles.empty());
  EXPECT_EQ(none.count, (std::array<int, 4>{0, 0, 0, 0}));
}

TEST(OrderTriangles, RefusesBadInputNamingIt) {
  const Triangles triangles = {{0, 1, 2}, {1, 2, 3}};
  const std::vector<TriangleFacts> one(1);
  try {
    order_triangles(triangles, one, {});
    ADD_FAILURE() << "accepted 1 fact for 2 triangles";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("facts"), std::string::npos) << e.what();
  }
  const std::vector<TriangleFacts> two(2);
  EXPECT_THROW(order_triangles(triangles, two, {false, 0, 0}), std::invalid_argument);
  EXPECT_THROW(order_triangles(triangles, two, {false, 0.1, NAN}), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
