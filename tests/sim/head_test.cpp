#include "sim/head.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "mesh/topology.h"
#include "render/renderer.h"
#include "tests/common/test_data.h"
#include "tests/sim/mesh_distance.h"
#include "vision/landmarks.h"

namespace orthoface::sim {
namespace {

HeadOptions fast_options() {
  HeadOptions o;
  o.texture_size = 128;  // topology and shape tests do not look at the texture
  return o;
}

TEST(HeadParams, SeedZeroIsTheAverageAndSeedsAreDeterministic) {
  const HeadParams avg;
  EXPECT_EQ(head_params(0).head_width, avg.head_width);
  EXPECT_EQ(head_params(0).nose_length, avg.nose_length);
  EXPECT_EQ(head_params(7).nose_width, head_params(7).nose_width);
  EXPECT_NE(head_params(7).nose_width, head_params(8).nose_width);
  for (int seed = 0; seed < 50; ++seed) EXPECT_NO_THROW(head_params(seed).check()) << seed;
  EXPECT_THROW(head_params(-1), std::invalid_argument);
}

TEST(HeadParams, RejectsBadValues) {
  HeadParams p;
  p.head_width = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(p.check(), std::invalid_argument);
  EXPECT_THROW(make_head(p), std::invalid_argument);
  p = HeadParams{};
  p.nose_length = -5;
  EXPECT_THROW(make_head(p), std::invalid_argument);
  p = HeadParams{};
  p.eye_spacing = 80;  // eyes wider than the head allows
  p.eye_width = 40;
  EXPECT_THROW(make_head(p), std::invalid_argument);
  p = HeadParams{};
  p.iris_rgb.x() = 2;
  EXPECT_THROW(make_head(p), std::invalid_argument);
}

TEST(HeadOptions, RejectsBadValues) {
  HeadOptions o;
  o.texture_size = 0;
  EXPECT_THROW(make_head(HeadParams{}, o), std::invalid_argument);
  o = HeadOptions{};
  o.rings = 40;
  o.segments = 41;  // odd: no midline column
  EXPECT_THROW(make_head(HeadParams{}, o), std::invalid_argument);
  o = HeadOptions{};
  o.target_triangles = -3;
  EXPECT_THROW(make_head(HeadParams{}, o), std::invalid_argument);
}

TEST(MakeHead, EverySeedIsClosedManifoldSphere) {
  for (int seed = 0; seed < 20; ++seed) {
    const Head h = make_head(head_params(seed), fast_options());
    const mesh::TopologyReport r = mesh::topology_report(h.mesh);
    EXPECT_TRUE(r.watertight()) << "seed " << seed;
    EXPECT_EQ(r.euler_characteristic, 2) << "seed " << seed;
    EXPECT_EQ(r.degenerate_triangles, 0) << "seed " << seed;
    EXPECT_EQ(r.non_manifold_vertices, 0) << "seed " << seed;
    EXPECT_EQ(r.inconsistent_edges, 0) << "seed " << seed;
  }
}

TEST(MakeHead, TriangleCountFollowsOptions) {
  const Head normal = make_head(HeadParams{}, fast_options());
  EXPECT_NEAR(static_cast<double>(normal.mesh.triangles.size()), 4000, 600);
  HeadOptions high = fast_options();
  high.target_triangles = HeadOptions::kHighTriangles;
  const Head fine = make_head(HeadParams{}, high);
  EXPECT_NEAR(static_cast<double>(fine.mesh.triangles.size()), 16000, 2400);
  EXPECT_TRUE(mesh::topology_report(fine.mesh).watertight());
  HeadOptions grid = fast_options();
  grid.rings = 20;  // the smallest grid still closes
  grid.segments = 16;
  const Head coarse = make_head(HeadParams{}, grid);
  EXPECT_EQ(coarse.mesh.triangles.size(), 2u * 16 * (20 + 1));
  EXPECT_TRUE(mesh::topology_report(coarse.mesh).watertight());
}

TEST(MakeHead, OutwardOrientationAndHumanSize) {
  const Head h = make_head(0);
  // Signed volume > 0 means outward normals; a head + neck is a few litres.
  double volume = 0;
  for (const auto& t : h.mesh.triangles)
    volume += h.mesh.vertices[t[0]].dot(h.mesh.vertices[t[1]].cross(h.mesh.vertices[t[2]])) / 6;
  EXPECT_GT(volume, 3.0e6);
  EXPECT_LT(volume, 8.0e6);
  const auto& lm = h.landmarks;
  EXPECT_NEAR(lm.at("ear_left_tragus").y(), 0, 1e-9);  // origin between the ears
  EXPECT_NEAR(lm.at("ear_left_tragus").x() + lm.at("ear_right_tragus").x(), 0, 1e-9);
  EXPECT_NEAR(lm.at("eye_left_center").x() - lm.at("eye_right_center").x(), 63, 1.0);
  EXPECT_GT(lm.at("nose_tip").z(), 95);
  EXPECT_EQ(h.name, "sim seed 0");
}

TEST(MakeHead, LandmarksExistLieOnTheSurfaceAndMirror) {
  for (int seed : {0, 3, 11}) {
    const Head h = make_head(head_params(seed), fast_options());
    for (const auto name : vision::kLandmarkNames) {
      const auto it = h.landmarks.find(std::string(name));
      ASSERT_NE(it, h.landmarks.end()) << name;
      EXPECT_LT(distance_to_mesh(h.mesh, it->second), 0.5) << name << " seed " << seed;
      const Eigen::Vector3d m = h.landmarks.at(vision::mirrored_name(name));
      EXPECT_NEAR(m.x(), -it->second.x(), 1e-6) << name;
      EXPECT_NEAR(m.y(), it->second.y(), 1e-6) << name;
      EXPECT_NEAR(m.z(), it->second.z(), 1e-6) << name;
    }
  }
}

TEST(MakeHead, ProfileLandmarksAreOrderedAndNoseTipIsMostForward) {
  for (int seed : {0, 5, 9}) {
    const Head h = make_head(head_params(seed), fast_options());
    const auto& l = h.landmarks;
    const char* order[] = {"forehead_top", "nose_bridge", "nose_tip", "subnasale",
                           "lip_upper",    "lip_lower",   "chin",     "chin_bottom"};
    for (int k = 0; k + 1 < 8; ++k)
      EXPECT_GT(l.at(order[k]).y(), l.at(order[k + 1]).y()) << order[k];
    double zmax = -1e9;
    for (const auto& v : h.mesh.vertices) zmax = std::max(zmax, v.z());
    EXPECT_NEAR(l.at("nose_tip").z(), zmax, 1e-9) << "seed " << seed;
    EXPECT_GT(l.at("eye_left_outer").x(), l.at("eye_left_center").x());
    EXPECT_GT(l.at("eye_left_center").x(), l.at("eye_left_inner").x());
    EXPECT_GT(l.at("brow_left_center").y(), l.at("eye_left_center").y() + 8);
    EXPECT_GT(l.at("alar_left").x(), 12);
    EXPECT_GT(l.at("ear_left_top").y(), l.at("ear_left_tragus").y() + 20);
  }
}

TEST(MakeHead, AsymmetryBreaksTheMirror) {
  HeadParams p;
  p.asymmetry = 1;
  const Head h = make_head(p, fast_options());
  EXPECT_GT(std::abs(h.landmarks.at("mouth_left").x() + h.landmarks.at("mouth_right").x()), 4.0);
  EXPECT_GT(h.landmarks.at("eye_left_center").y() - h.landmarks.at("eye_right_center").y(), 1.5);
  EXPECT_TRUE(mesh::topology_report(h.mesh).watertight());
}

TEST(MakeHead, TenSeedsGiveVisiblyDifferentHeads) {
  std::vector<Head> heads;
  for (int seed = 1; seed <= 10; ++seed)
    heads.push_back(make_head(head_params(seed), fast_options()));
  // Per-vertex RMS distance between two heads after centring (same grid => same vertex count).
  double min_rms = 1e9, sum_rms = 0;
  int pairs = 0;
  for (size_t a = 0; a < heads.size(); ++a)
    for (size_t b = a + 1; b < heads.size(); ++b) {
      const auto& va = heads[a].mesh.vertices;
      const auto& vb = heads[b].mesh.vertices;
      ASSERT_EQ(va.size(), vb.size());
      Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
      for (size_t i = 0; i < va.size(); ++i) {
        ca += va[i] / va.size();
        cb += vb[i] / vb.size();
      }
      double s = 0;
      for (size_t i = 0; i < va.size(); ++i) s += ((va[i] - ca) - (vb[i] - cb)).squaredNorm();
      const double rms = std::sqrt(s / va.size());
      min_rms = std::min(min_rms, rms);
      sum_rms += rms;
      ++pairs;
    }
  // Landmark spread: RMS over landmarks of each landmark's standard deviation across seeds.
  double spread = 0;
  for (const auto name : vision::kLandmarkNames) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& h : heads) mean += h.landmarks.at(std::string(name)) / heads.size();
    double var = 0;
    for (const auto& h : heads)
      var += (h.landmarks.at(std::string(name)) - mean).squaredNorm() / heads.size();
    spread += var / vision::kLandmarkNames.size();
  }
  spread = std::sqrt(spread);
  RecordProperty("min_pair_rms_mm", std::to_string(min_rms));
  RecordProperty("mean_pair_rms_mm", std::to_string(sum_rms / pairs));
  RecordProperty("landmark_spread_mm", std::to_string(spread));
  std::printf(
      "shape spread over seeds 1..10: min pair RMS %.2f mm, mean pair RMS %.2f mm, "
      "landmark spread %.2f mm\n",
      min_rms, sum_rms / pairs, spread);
  EXPECT_GT(min_rms, 2.0);
  EXPECT_GT(sum_rms / pairs, 5.0);
  EXPECT_GT(spread, 3.0);
}

TEST(MakeHead, IsDeterministic) {
  const Head a = make_head(4), b = make_head(4);
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  for (size_t i = 0; i < a.mesh.vertices.size(); ++i)
    EXPECT_EQ(a.mesh.vertices[i], b.mesh.vertices[i]);
  EXPECT_EQ(cv::norm(a.mesh.texture, b.mesh.texture, cv::NORM_INF), 0);
}

TEST(SilhouetteExtremes, MatchesSectionsAndTheRenderedMask) {
  const Head h = make_head(2);
  const auto rig = capture::ideal_rig(400, 600, 1.5);
  render::Renderer renderer;
  const render::RenderResult front = renderer.render(h.mesh, rig.front);
  const render::RenderResult side = renderer.render(h.mesh, rig.side);
  for (double y_mm : {90.0, 40.0, 10.0, -20.0, -60.0, -150.0}) {
    // Compare on a pixel row: its centre's height is what the mask samples.
    const int row = static_cast<int>(std::floor(capture::project(rig.front, {0, y_mm, 0}).y()));
    const double y = (rig.front.cy - (row + 0.5)) / rig.front.fy;
    ASSERT_NEAR(capture::project(rig.front, {0, y, 0}).y(), row + 0.5, 1e-9);
    const auto e = silhouette_extremes(h, y);
    ASSERT_TRUE(e.has_value()) << y;
    EXPECT_NEAR(e->min_x, -e->max_x, 1e-6);
    int first = -1, last = -1;
    for (int c = 0; c < front.mask.cols; ++c)
      if (front.mask.at<uchar>(row, c)) {
        if (first < 0) first = c;
        last = c;
      }
    ASSERT_GE(first, 0) << y;
    EXPECT_NEAR(capture::project(rig.front, {e->min_x, y, 0}).x(), first, 1.0) << y;
    EXPECT_NEAR(capture::project(rig.front, {e->max_x, y, 0}).x(), last + 1, 1.0) << y;
    // Side view: the face side of the profile (+z) is the image left; same rows (seed 004 eq. 1).
    int sfirst = -1;
    for (int c = 0; c < side.mask.cols && sfirst < 0; ++c)
      if (side.mask.at<uchar>(row, c)) sfirst = c;
    EXPECT_NEAR(capture::project(rig.side, {0, y, e->max_z}).x(), sfirst, 1.0) << y;
  }
  EXPECT_FALSE(silhouette_extremes(h, 1000).has_value());
  EXPECT_THROW(silhouette_extremes(h, std::nan("")), std::invalid_argument);
}

TEST(HeadTexture, FrontViewShowsPupilsLipsAndSkinAtTheLandmarks) {
  for (int seed : {0, 6}) {
    const Head h = make_head(seed);
    const auto rig = capture::ideal_rig(400, 600, 2.0);
    const render::RenderResult front = render::render_once(h.mesh, rig.front);
    auto bgr = [&](const std::string& name) {
      const Eigen::Vector2d px = capture::project(rig.front, h.landmarks.at(name));
      return front.image.at<cv::Vec3b>(static_cast<int>(px.y()), static_cast<int>(px.x()));
    };
    auto lum = [](const cv::Vec3b& c) { return (c[0] + c[1] + c[2]) / 3.0; };
    // Skin reference: the cheek between the nose wing and the outer eye corner.
    const Eigen::Vector2d ref =
        0.5 * (capture::project(rig.front, h.landmarks.at("alar_left")) +
               capture::project(rig.front, h.landmarks.at("eye_left_outer")));
    const cv::Vec3b cheek =
        front.image.at<cv::Vec3b>(static_cast<int>(ref.y()), static_cast<int>(ref.x()));
    for (const char* eye : {"eye_left_center", "eye_right_center"})
      EXPECT_LT(lum(bgr(eye)), 0.4 * lum(cheek)) << eye << " seed " << seed;  // pupil
    const cv::Vec3b lip = bgr("lip_lower");
    EXPECT_GT(lip[2] - lip[1], cheek[2] - cheek[1] + 10) << "seed " << seed;  // redder than skin
    EXPECT_GT(lum(cheek), 60) << "seed " << seed;
  }
}

}  // namespace
}  // namespace orthoface::sim

namespace orthoface::sim {
namespace {

// Renders seeds 0..2 front / 45 degrees / side with light, as a person would look at them
// (PNG sheets in the test temp dir: orthoface_test_head_views/seed_N.png), and checks what a
// face must show: left-right symmetric front silhouette, the head filling a human-sized area.
TEST(HeadRender, FrontSideAnd45ViewsLookLikeAHead) {
  const auto dir = testing::temp_dir("head_views");
  render::Renderer renderer;
  capture::CameraModel cam;
  cam.width = 400;
  cam.height = 480;
  cam.fx = cam.fy = 1.4;  // pixels per mm, orthographic
  cam.cx = 200;
  cam.cy = 250;
  render::RenderOptions ro;
  ro.background = {200, 200, 200};
  ro.light.ambient = 0.55;
  ro.light.diffuse = 0.55;
  ro.light.direction_head = Eigen::Vector3d(0.3, -0.4, -1).normalized();
  for (int seed = 0; seed < 3; ++seed) {
    const Head h = make_head(seed);
    std::vector<cv::Mat> views;
    for (double yaw_deg : {0.0, 45.0, 90.0}) {
      const auto c = capture::camera_at(cam, yaw_deg * M_PI / 180, 0, 1000);
      const render::RenderResult r = renderer.render(h.mesh, c, ro);
      const double area_mm2 = cv::countNonZero(r.mask) / (cam.fx * cam.fy);
      EXPECT_GT(area_mm2, 3.5e4) << "seed " << seed << " yaw " << yaw_deg;
      EXPECT_LT(area_mm2, 8.0e4) << "seed " << seed << " yaw " << yaw_deg;
      if (yaw_deg == 0) {
        cv::Mat flipped;
        cv::flip(r.mask, flipped, 1);
        // x = 0 is the boundary between columns 199 and 200, so the mirror is a plain flip.
        EXPECT_LT(cv::norm(r.mask, flipped, cv::NORM_L1) / 255.0, 0.01 * cv::countNonZero(r.mask));
      }
      views.push_back(r.image);
    }
    cv::Mat sheet;
    cv::hconcat(views, sheet);
    EXPECT_TRUE(cv::imwrite((dir / ("seed_" + std::to_string(seed) + ".png")).string(), sheet));
  }
}

}  // namespace
}  // namespace orthoface::sim
