// The face's flanks set back where the two photos agree (reconstruct/flank_depth.h).
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "reconstruct/flank_depth.h"
#include "reconstruct/reconstruction.h"
#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::reconstruct {
namespace {

struct Fitted {
  sim::Capture cap;
  Reconstruction rec;
};

// A sim head reconstructed through its rig (the pipeline fits the flanks itself).
const Fitted& fitted() {
  static const Fitted f = [] {
    Fitted out;
    out.cap = sim::simulate_capture(sim::make_head(3), sim::RigOptions{});
    ReconstructOptions o;
    o.rig = out.cap.nominal_rig;
    out.rec = from_photos(out.cap.front, out.cap.side, o);
    return out;
  }();
  return f;
}

// The sim heads' flanks are where their photos put them: nothing moves.
TEST(FlankDepth, LeavesASimHeadsFlanksWhereThePhotosAgree) {
  const Reconstruction& r = fitted().rec;
  EXPECT_EQ(r.report.flanks.offset_mm, 0.0);
  EXPECT_EQ(r.report.flanks.offset_below_mm, 0.0);
  EXPECT_GT(r.report.flanks.points, 200);
  EXPECT_GT(r.report.flanks.agreement_before, 0.2);
  EXPECT_TRUE(r.report.flanks.weight.empty());  // the report keeps the figures only
}

// Flanks pushed 6 mm forward above the nose tip (the fault real faces show) are found and set
// back, and the face below it, where nothing moved, stays.
TEST(FlankDepth, FindsFlanksPushedForwardAndSetsThemBack) {
  const Fitted& f = fitted();
  mesh::TriMesh pushed = f.rec.mesh;
  std::map<std::string, Eigen::Vector3d> landmarks = f.rec.landmarks;
  FlankDepth push = fit_flank_depth(pushed, f.rec.front, f.rec.side, f.rec.photo_rig);
  push.offset_mm = -6;
  push.offset_below_mm = 0;
  move_flanks(push, f.rec.photo_rig.front, pushed, landmarks);
  const FlankDepth found = fit_flank_depth(pushed, f.rec.front, f.rec.side, f.rec.photo_rig);
  EXPECT_NEAR(found.offset_mm, 6, 2);
  EXPECT_NEAR(found.offset_below_mm, 0, 1.5);
  EXPECT_GT(found.agreement_after, found.agreement_before + 0.05);
  move_flanks(found, f.rec.photo_rig.front, pushed, landmarks);
  double worst = 0;
  for (size_t i = 0; i < pushed.vertices.size(); ++i)
    worst = std::max(worst, (pushed.vertices[i] - f.rec.mesh.vertices[i]).norm());
  EXPECT_LT(worst, 2.0);
}

// With the bands off one offset moves the whole face: flanks pushed forward everywhere are set
// back everywhere.
TEST(FlankDepth, OneOffsetForTheWholeFaceWithoutBands) {
  const Fitted& f = fitted();
  mesh::TriMesh pushed = f.rec.mesh;
  std::map<std::string, Eigen::Vector3d> landmarks = f.rec.landmarks;
  FlankDepthOptions one;
  one.bands = false;
  FlankDepth push = fit_flank_depth(pushed, f.rec.front, f.rec.side, f.rec.photo_rig, one);
  for (double b : push.below) ASSERT_EQ(b, 0.0);
  push.offset_mm = -6;
  move_flanks(push, f.rec.photo_rig.front, pushed, landmarks);
  const FlankDepth found = fit_flank_depth(pushed, f.rec.front, f.rec.side, f.rec.photo_rig, one);
  EXPECT_NEAR(found.offset_mm, 6, 2);
  EXPECT_EQ(found.offset_below_mm, found.offset_mm);
  EXPECT_GT(found.agreement_after, found.agreement_before + 0.05);
}

// The mesh's edge (where the head hull meets it) and its midline do not move; the flanks the
// side photo sees do, straight back along the front camera's axis, and a landmark with them.
TEST(FlankDepth, MovesTheSeenFlankBackAndLeavesTheEdgeAndMidline) {
  const Fitted& f = fitted();
  mesh::TriMesh m = f.rec.mesh;
  std::map<std::string, Eigen::Vector3d> landmarks = f.rec.landmarks;
  FlankDepth d = fit_flank_depth(m, f.rec.front, f.rec.side, f.rec.photo_rig);
  ASSERT_EQ(d.weight.size(), m.vertices.size());
  d.offset_mm = d.offset_below_mm = 5;
  move_flanks(d, f.rec.photo_rig.front, m, landmarks);
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      ++uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  std::set<int> edge;
  for (const auto& [e, n] : uses)
    if (n == 1) edge.insert(e.first), edge.insert(e.second);
  ASSERT_FALSE(edge.empty());
  double moved_max = 0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const Eigen::Vector3d delta = m.vertices[i] - f.rec.mesh.vertices[i];
    EXPECT_NEAR(delta.x(), 0, 1e-9);
    EXPECT_NEAR(delta.y(), 0, 1e-9);
    EXPECT_LE(delta.z(), 1e-9);  // back, never forward
    if (edge.count(int(i))) {
      EXPECT_NEAR(delta.z(), 0, 1e-9) << "edge vertex " << i;
    }
    moved_max = std::max(moved_max, -delta.z());
  }
  EXPECT_GT(moved_max, 4.0);
  EXPECT_NEAR((landmarks.at("nose_tip") - f.rec.landmarks.at("nose_tip")).norm(), 0, 0.5);
  // The flank's vertices move on the side the side camera stands, not on the other.
  const double side_x = f.rec.photo_rig.side.cam_from_head.inverse().translation().x();
  double seen = 0, other = 0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const double dz = f.rec.mesh.vertices[i].z() - m.vertices[i].z();
    (f.rec.mesh.vertices[i].x() * side_x > 0 ? seen : other) += dz;
  }
  EXPECT_GT(seen, 10 * other);
}

TEST(FlankDepth, BadInputsAreRefused) {
  const Fitted& f = fitted();
  const auto& r = f.rec;
  const std::vector<std::function<void(FlankDepthOptions&)>> bad = {
      [](auto& o) { o.min_mm = 1; },        [](auto& o) { o.max_mm = NAN; },
      [](auto& o) { o.step_mm = 0; },       [](auto& o) { o.fine_mm = 7; },
      [](auto& o) { o.min_cos = 1; },       [](auto& o) { o.min_gain = -0.1; },
      [](auto& o) { o.min_points = 2; },    [](auto& o) { o.blend_mm = 0; },
      [](auto& o) { o.below_max_mm = -1; }, [](auto& o) { o.below_max_mm = INFINITY; }};
  FlankDepthOptions o;
  for (size_t i = 0; i < bad.size(); ++i) {
    o = {};
    bad[i](o);
    EXPECT_THROW(o.check(), std::invalid_argument) << "bad option " << i;
  }
  EXPECT_THROW(fit_flank_depth(r.mesh, r.front, r.side, r.photo_rig, o), std::invalid_argument);
  EXPECT_THROW(fit_flank_depth(mesh::TriMesh{}, r.front, r.side, r.photo_rig),
               std::invalid_argument);
  EXPECT_THROW(fit_flank_depth(r.mesh, cv::Mat(), r.side, r.photo_rig), std::invalid_argument);
  cv::Mat bgra;
  cv::cvtColor(r.side, bgra, cv::COLOR_BGR2BGRA);
  EXPECT_THROW(fit_flank_depth(r.mesh, r.front, bgra, r.photo_rig), std::invalid_argument);
  cv::Mat half;
  cv::resize(r.side, half, cv::Size(), 0.5, 0.5);
  EXPECT_THROW(fit_flank_depth(r.mesh, r.front, half, r.photo_rig), std::invalid_argument);
  FlankDepth wrong;
  wrong.offset_mm = 3;
  wrong.weight.assign(3, 1.0);
  mesh::TriMesh m = r.mesh;
  std::map<std::string, Eigen::Vector3d> lm;
  EXPECT_THROW(move_flanks(wrong, r.photo_rig.front, m, lm), std::invalid_argument);
  wrong.weight.assign(m.vertices.size(), 1.0);  // the heights' shares missing
  EXPECT_THROW(move_flanks(wrong, r.photo_rig.front, m, lm), std::invalid_argument);
  // Too few points seen by both photos: nothing moves, and the caller is told how many there were.
  FlankDepthOptions many;
  many.min_points = 1000000;
  const FlankDepth none = fit_flank_depth(r.mesh, r.front, r.side, r.photo_rig, many);
  EXPECT_EQ(none.offset_mm, 0.0);
  EXPECT_TRUE(std::isnan(none.agreement_before));
  EXPECT_GT(none.points, 0);
}

}  // namespace
}  // namespace orthoface::reconstruct
