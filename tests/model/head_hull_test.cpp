// The head hull from two silhouettes of a known head (an ellipsoid on a neck cylinder).
#include "model/head_hull.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "mesh/topology.h"

namespace orthoface::model {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The known head: an ellipsoid (semi-axes 75 x 110 x 95 mm, centre (0, 20, -10)) on a neck
// cylinder of radius 50 around (0, *, -20) from y = -60 down past the frame.
struct KnownHead {
  capture::RigCalibration rig = capture::ideal_rig(640, 480, 1.3);
  cv::Mat front, side;

  KnownHead() {
    front = silhouette(
        rig.front,
        [](double t) { return Eigen::Vector3d(75 * std::cos(t), 20 + 110 * std::sin(t), 0); },
        {{-50, -60}, {50, -60}, {50, -300}, {-50, -300}}, true);
    side = silhouette(
        rig.side,
        [](double t) { return Eigen::Vector3d(0, 20 + 110 * std::sin(t), -10 + 95 * std::cos(t)); },
        {{-70, -60}, {30, -60}, {30, -300}, {-70, -300}}, false);
  }

  template <typename Outline>
  cv::Mat silhouette(const capture::CameraModel& cam, Outline outline,
                     const std::vector<std::pair<double, double>>& neck, bool front_view) {
    cv::Mat m(cam.height, cam.width, CV_8U, cv::Scalar(0));
    std::vector<cv::Point> head;
    for (int i = 0; i < 360; ++i) {
      const Eigen::Vector2d p = capture::project(cam, outline(2 * kPi * i / 360));
      head.emplace_back(int(std::lround(p.x())), int(std::lround(p.y())));
    }
    std::vector<cv::Point> neck_px;
    for (const auto& [a, y] : neck) {
      const Eigen::Vector3d p = front_view ? Eigen::Vector3d(a, y, 0) : Eigen::Vector3d(0, y, a);
      const Eigen::Vector2d q = capture::project(cam, p);
      neck_px.emplace_back(int(std::lround(q.x())), int(std::lround(q.y())));
    }
    cv::fillPoly(m, std::vector<std::vector<cv::Point>>{head}, cv::Scalar(255));
    cv::fillPoly(m, std::vector<std::vector<cv::Point>>{neck_px}, cv::Scalar(255));
    return m;
  }
};

// A face patch in front of the ellipsoid: z = 60 - (x^2 + y^2) / 150 over |x|, |y| <= 40.
mesh::TriMesh face_patch() {
  mesh::TriMesh m;
  const int n = 17;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -40 + 80.0 * i / (n - 1), y = -40 + 80.0 * j / (n - 1);
      m.vertices.emplace_back(x, y, 60 - (x * x + y * y) / 150);
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      m.triangles.push_back({a, a + 1, a + n});
      m.triangles.push_back({a + 1, a + n + 1, a + n});
    }
  return m;
}

double signed_volume(const mesh::TriMesh& m) {
  double v = 0;
  for (const auto& t : m.triangles)
    v += m.vertices[size_t(t[0])].dot(m.vertices[size_t(t[1])].cross(m.vertices[size_t(t[2])]));
  return v / 6;
}

TEST(HeadHull, IsAClosedOutwardHeadOfTheSilhouettesExtent) {
  const KnownHead k;
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face_patch());
  ASSERT_FALSE(hull.mesh.triangles.empty());
  const mesh::TopologyReport t = mesh::topology_report(hull.mesh);
  EXPECT_TRUE(t.closed());
  EXPECT_TRUE(t.manifold());
  EXPECT_GT(signed_volume(hull.mesh), 0);  // outward triangles
  // Width and depth at the ellipsoid's equator (y = 20) and its top.
  double x_lo = 1e9, x_hi = -1e9, z_lo = 1e9, z_hi = -1e9, top = -1e9;
  for (const auto& v : hull.mesh.vertices) {
    top = std::max(top, v.y());
    if (std::abs(v.y() - 20) > 1.01) continue;
    x_lo = std::min(x_lo, v.x()), x_hi = std::max(x_hi, v.x());
    z_lo = std::min(z_lo, v.z()), z_hi = std::max(z_hi, v.z());
  }
  EXPECT_NEAR(x_hi - x_lo, 150, 4);
  EXPECT_NEAR(z_lo, -105, 3);  // the back of the head
  EXPECT_NEAR(top, 130, 3);
  EXPECT_LT(z_hi, 60);  // the front stays behind the face patch (60 at its centre)
}

TEST(HeadHull, StaysBehindTheFaceWhereTheFaceCoversIt) {
  const KnownHead k;
  const mesh::TriMesh face = face_patch();
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face);
  int in_front = 0, under_face = 0;
  for (const auto& v : hull.mesh.vertices) {
    if (std::abs(v.x()) > 35 || std::abs(v.y()) > 35 || v.z() < 0) continue;
    ++under_face;
    if (v.z() > 60 - (v.x() * v.x() + v.y() * v.y()) / 150 - 1) ++in_front;
  }
  EXPECT_GT(under_face, 50);
  EXPECT_EQ(in_front, 0);
}

// Inside, the hull keeps its inset behind the face; at the face's top edge it meets the face
// flush, so no strip of hull that the front photo sees hidden shows past the edge from above.
TEST(HeadHull, MeetsTheFacesTopEdgeFlush) {
  const KnownHead k;
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face_patch());
  double edge_gap = 0, inner_gap = 1e9;
  int edge_n = 0, inner_n = 0;
  for (const auto& v : hull.mesh.vertices) {
    if (v.z() < 0 || std::abs(v.x()) > 25) continue;
    const double gap = 60 - (v.x() * v.x() + v.y() * v.y()) / 150 - v.z();  // behind the face
    if (v.y() >= 38.9 && v.y() <= 40.1) edge_gap = std::max(edge_gap, gap), ++edge_n;
    if (std::abs(v.y()) < 25) inner_gap = std::min(inner_gap, gap), ++inner_n;
  }
  ASSERT_GT(edge_n, 5);
  ASSERT_GT(inner_n, 50);
  EXPECT_LT(edge_gap, 1.0);
  EXPECT_GT(inner_gap, 2.5);
}

// Shoulders in the front silhouette: 130 mm to each side of the midline from height top_y (mm)
// down past the frame.
void add_shoulders(KnownHead& k, double top_y) {
  const Eigen::Vector2d a = capture::project(k.rig.front, {-130, top_y, 0});
  const Eigen::Vector2d b = capture::project(k.rig.front, {130, -400, 0});
  cv::rectangle(k.front, cv::Point(int(a.x()), int(a.y())), cv::Point(int(b.x()), int(b.y())),
                cv::Scalar(255), cv::FILLED);
}

TEST(HeadHull, TurnsAboutTheNeckAndStopsItAtTheShoulders) {
  KnownHead k;
  add_shoulders(k, -140);  // 2.5 x the neck's width, 100 mm below the face
  HullOptions o;
  o.max_neck_mm = 200;
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face_patch(), o);
  ASSERT_TRUE(hull.pivot.allFinite());
  EXPECT_NEAR(hull.pivot.x(), 0, 2);
  // 10..40 mm below the face: the ellipsoid's bottom (centre z = -10) meets the neck (z = -20).
  EXPECT_GT(hull.pivot.z(), -21);
  EXPECT_LT(hull.pivot.z(), -9);
  // Past the shoulders the neck goes on at its own width.
  double widest = 0;
  for (const auto& v : hull.mesh.vertices)
    if (v.y() < -150) widest = std::max(widest, std::abs(v.x()));
  EXPECT_GT(widest, 45);
  EXPECT_LT(widest, 52);
}

// A short neck: the front silhouette reaches the shoulders above the face's lowest point (a
// dark shirt merged with the neck). Beside the jaw and below it the hull keeps the width of the
// last slice before the shoulders, not a slab as wide as them.
TEST(HeadHull, ShouldersAboveTheChinDoNotWidenTheNeck) {
  KnownHead k;
  add_shoulders(k, -30);
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face_patch());
  ASSERT_FALSE(hull.mesh.triangles.empty());
  ASSERT_TRUE(hull.pivot.allFinite());
  EXPECT_NEAR(hull.pivot.x(), 0, 2);
  // The ellipsoid's half width 28 mm below the face's middle, where the shoulders begin: 67 mm.
  double beside_jaw = 0, below = 0;
  for (const auto& v : hull.mesh.vertices) {
    if (v.y() < -32 && v.y() > -40) beside_jaw = std::max(beside_jaw, std::abs(v.x()));
    if (v.y() < -50) below = std::max(below, std::abs(v.x()));
  }
  EXPECT_GT(beside_jaw, 55);
  EXPECT_LT(beside_jaw, 72);
  EXPECT_GT(below, 55);
  EXPECT_LT(below, 72);
}

// The side photo's cut misses the top of the head (hair on a dark curtain, a pair not taken at
// one height): the head still reaches the front silhouette's top, narrowing in depth as in width.
TEST(HeadHull, ReachesTheFrontSilhouettesTopAboveTheSides) {
  KnownHead k;
  const Eigen::Vector2d cut = capture::project(k.rig.side, {0, 100, 0});
  k.side.rowRange(0, int(cut.y())).setTo(0);  // nothing above y = 100 mm in the side photo
  const HeadHull hull = head_hull(k.front, k.side, k.rig, face_patch());
  ASSERT_FALSE(hull.mesh.triangles.empty());
  EXPECT_TRUE(mesh::topology_report(hull.mesh).closed());
  double top = -1e9, depth_high = 0, width_high = 0;
  for (const auto& v : hull.mesh.vertices) {
    top = std::max(top, v.y());
    if (std::abs(v.y() - 120) > 1.01) continue;  // above the side's top
    depth_high = std::max(depth_high, std::abs(v.z() + 10));
    width_high = std::max(width_high, std::abs(v.x()));
  }
  EXPECT_NEAR(top, 130, 3);  // the front's top, not the side's 100
  // At y = 120 the ellipsoid is 75 * sqrt(1 - (100 / 110)^2) = 31 mm wide each way; the depth
  // follows the width from the last slice both photos hold, so it is no deeper than the head's
  // 95 mm there and far less than at the equator.
  EXPECT_NEAR(width_high, 31, 4);
  EXPECT_GT(depth_high, 5);
  EXPECT_LT(depth_high, 60);
}

TEST(HeadHull, NoHeadAroundTheFaceGivesNoHull) {
  const KnownHead k;
  const cv::Mat nothing(k.front.size(), CV_8U, cv::Scalar(0));
  EXPECT_TRUE(head_hull(nothing, k.side, k.rig, face_patch()).mesh.triangles.empty());
}

TEST(HeadHull, BadInputIsRefusedNamingIt) {
  const KnownHead k;
  const mesh::TriMesh face = face_patch();
  auto message = [&](const cv::Mat& front, const cv::Mat& side, const mesh::TriMesh& f,
                     const HullOptions& o) {
    try {
      head_hull(front, side, k.rig, f, o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({}, k.side, face, {}).find("front silhouette is empty"), std::string::npos);
  cv::Mat small;
  cv::resize(k.side, small, {}, 0.5, 0.5);
  EXPECT_NE(message(k.front, small, face, {}).find("side silhouette is 320x240"),
            std::string::npos);
  cv::Mat colour;
  cv::cvtColor(k.front, colour, cv::COLOR_GRAY2BGR);
  EXPECT_NE(message(colour, k.side, face, {}).find("not 8-bit single-channel"), std::string::npos);
  EXPECT_NE(message(k.front, k.side, {}, {}).find("face mesh"), std::string::npos);
  HullOptions bad;
  bad.angles = 3;
  EXPECT_NE(message(k.front, k.side, face, bad).find("angles"), std::string::npos);
  bad = {};
  bad.collar_widening = 1;
  EXPECT_NE(message(k.front, k.side, face, bad).find("collar_widening"), std::string::npos);
}

TEST(Combined, AppendsTheSecondMeshAfterTheFirst) {
  const mesh::TriMesh a = face_patch();
  mesh::TriMesh b;
  b.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  b.triangles = {{0, 1, 2}};
  const mesh::TriMesh m = combined(a, b);
  ASSERT_EQ(m.vertices.size(), a.vertices.size() + 3);
  ASSERT_EQ(m.triangles.size(), a.triangles.size() + 1);
  const int n = int(a.vertices.size());
  EXPECT_EQ(m.triangles.back(), (std::array<int, 3>{n, n + 1, n + 2}));
  mesh::TriMesh coloured = a;
  coloured.colors.assign(a.vertices.size(), Eigen::Vector3d(1, 0, 0));
  EXPECT_TRUE(combined(coloured, b).colors.empty());  // b has none: dropped, not half-filled
}

}  // namespace
}  // namespace orthoface::model
