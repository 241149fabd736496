// Texture inheritance with live photos: new photos for the same mesh, and the colour match
// between the photos kept or recomputed.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "tests/render/new_view_scene.h"

namespace orthoface::render {
namespace {

using namespace testing;

TEST(NewView, NewPhotosReplaceTheOldWithoutANewMesh) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 30);
  const cv::Mat front2 = 255 - s.front, side2 = 255 - s.side;
  const RenderResult before = synth.render(cam).view;
  synth.set_photos(front2, side2, ColourUpdate::Recompute);
  const RenderResult after = synth.render(cam).view;
  EXPECT_GT(cv::norm(before.image, after.image, cv::NORM_L1), 1e6);
  const RenderResult fresh = synthesize_view(s.bare, s.rig, front2, side2, cam).view;
  EXPECT_EQ(cv::norm(fresh.image, after.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(synth.render(cam).view.image, after.image, cv::NORM_INF), 0.0);
}

TEST(NewView, LivePhotosKeepTheColourMatchAndUpdateTheTextures) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 30);
  const ColourMatch first = synth.colour_match();
  const RenderResult original = synth.render(cam).view;
  const cv::Mat front2 = 255 - s.front, side2 = 255 - s.side;
  synth.set_photos(front2, side2);  // Keep: the statistics of the first photos stay
  EXPECT_EQ(synth.colour_match().samples, first.samples);
  EXPECT_EQ(synth.colour_match().mean[1], first.mean[1]);
  SynthesisOptions raw;
  raw.equalize = false;
  raw.source_weights = true;
  const SynthesisResult fresh_raw = synthesize_view(s.bare, s.rig, front2, side2, cam, raw);
  cv::Mat seen;  // the fill colour (where no photo sees) belongs to the match: left out
  cv::extractChannel(fresh_raw.weights, seen, 2);
  seen = (seen == 0) & fresh_raw.view.mask;
  ASSERT_GT(cv::countNonZero(seen), 50000);
  EXPECT_EQ(cv::norm(fresh_raw.view.image, synth.render(cam, raw).view.image, cv::NORM_INF, seen),
            0.0);
  // Twice more with new photos: back to the first pair gives the first view exactly.
  synth.set_photos(s.front * 0.5, s.side * 0.5);
  synth.set_photos(s.front, s.side);
  EXPECT_EQ(cv::norm(original.image, synth.render(cam).view.image, cv::NORM_INF), 0.0);
}

TEST(NewView, KeptColourMatchFollowsTheMappingOfTheFirstPhotos) {
  // Front pixels at yaw 0 of a kept match are the first match's mapping of the new photo.
  mesh::TriMesh ball = uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 32, 64);
  ball.colors.assign(ball.vertices.size(), {0.8, 0.6, 0.5});
  Scene s = make_scene(ball, capture::ideal_rig(400, 400, 2.0));
  cv::Mat dark_side;
  s.side.convertTo(dark_side, CV_8U, 0.6, 10);
  ViewSynthesizer synth(s.bare, s.rig, s.front, dark_side);
  const ColourMatch match = synth.colour_match();
  const cv::Mat front2 = s.front * 0.9;
  synth.set_photos(front2, dark_side);
  SynthesisOptions o;
  o.source_weights = true;
  const SynthesisResult r = synth.render(s.rig.front, o);
  const cv::Mat front_only = only_from_front(r);
  ASSERT_GT(cv::countNonZero(front_only), 10000);
  const cv::Mat expected = detail::equalized(front2, match, 0);
  cv::Mat diff;
  cv::absdiff(expected, r.view.image, diff);
  EXPECT_LE(cv::mean(diff, front_only)[0], 1.0);  // lookup-grid interpolation: about 1 level
  // A lighting change: recomputing the match removes the step the kept one leaves.
  synth.set_photos(s.front, s.side);
  const double kept_step = cv::norm(synth.colour_match().mean[0] - synth.colour_match().mean[1]);
  synth.update_colour_match();
  EXPECT_GT(kept_step, 10);
  EXPECT_LT(cv::norm(synth.colour_match().mean[0] - synth.colour_match().mean[1]), 2);
}

TEST(NewView, BadPhotosLeaveTheOldPhotosInPlace) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 30);
  const RenderResult before = synth.render(cam).view;
  cv::Mat small;
  cv::resize(s.side, small, cv::Size(320, 240));
  EXPECT_THROW(synth.set_photos(255 - s.front, small), std::invalid_argument);
  EXPECT_THROW(synth.set_photos(cv::Mat(), s.side, ColourUpdate::Recompute), std::invalid_argument);
  cv::Mat f32;
  s.front.convertTo(f32, CV_32F);
  EXPECT_THROW(synth.set_photos(f32, s.side), std::invalid_argument);
  EXPECT_EQ(cv::norm(before.image, synth.render(cam).view.image, cv::NORM_INF), 0.0);
}

// `rig` seeing the head moved by the pose (yaw about +y, then translation), as a head tracker
// reports it.
capture::RigCalibration posed_rig(const capture::RigCalibration& rig, double yaw_deg,
                                  const Eigen::Vector3d& t) {
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  capture::RigCalibration posed = rig;
  posed.front = capture::posed_camera(rig.front, r, t);
  posed.side = capture::posed_camera(rig.side, r, t);
  return posed;
}

TEST(NewView, SetRigRendersAsASynthesizerBuiltOnTheNewRig) {
  const Scene s = ellipsoid_scene();
  capture::RigCalibration perspective = sim::true_rig([] {
    sim::RigOptions o;
    o.kind = sim::RigKind::Perspective;
    return o;
  }());
  // A posed rig keeps the shader programs; a perspective one rebuilds them.
  for (const capture::RigCalibration& b :
       {posed_rig(s.rig, 12, Eigen::Vector3d(4, -3, 6)), perspective}) {
    ViewSynthesizer moved(s.bare, s.rig, s.front, s.side);
    SynthesisOptions sorted;  // the per-pixel fast path: triangle classes from the rig
    sorted.float_textures = false;
    sorted.source_weights = true;
    for (double yaw : {0.0, 40.0}) moved.render(view(s.rig.front, yaw), sorted);  // warm caches
    // There and back again: the first rig's views come back (the match is kept, the photos
    // re-equalised where the footprints moved).
    std::vector<cv::Mat> first;
    for (double yaw : {-20.0, 30.0})
      first.push_back(moved.render(view(s.rig.front, yaw)).view.image);
    moved.set_rig(b);
    moved.set_rig(s.rig);
    for (int k = 0; k < 2; ++k) {
      const cv::Mat again = moved.render(view(s.rig.front, k ? 30.0 : -20.0)).view.image;
      EXPECT_EQ(cv::norm(first[k], again, cv::NORM_INF), 0.0);
    }
    moved.set_rig(b);
    moved.update_colour_match();  // set_rig keeps the first rig's match
    ViewSynthesizer fresh(s.bare, b, s.front, s.side);
    for (int k = 0; k < 2; ++k)
      EXPECT_EQ(cv::norm(moved.source_depth(k), fresh.source_depth(k), cv::NORM_INF), 0.0);
    for (double yaw : {-20.0, 0.0, 40.0, 80.0})
      for (const SynthesisOptions& o : {SynthesisOptions{}, sorted}) {
        const CameraModel cam = view(b.front, yaw, 5);
        const SynthesisResult x = moved.render(cam, o), y = fresh.render(cam, o);
        ASSERT_GT(cv::countNonZero(y.view.mask), 10000);
        EXPECT_EQ(cv::norm(x.view.image, y.view.image, cv::NORM_INF), 0.0) << "yaw " << yaw;
        EXPECT_EQ(cv::norm(x.view.mask, y.view.mask, cv::NORM_INF), 0.0);
        if (!y.weights.empty()) {
          EXPECT_EQ(cv::norm(x.weights, y.weights, cv::NORM_INF), 0.0);
        }
      }
  }
}

TEST(NewView, BadRigThrowsAndLeavesTheSynthesizerUsable) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 30);
  const RenderResult before = synth.render(cam).view;
  capture::RigCalibration small = s.rig;
  small.side.width = 320;  // not the side photo's size
  try {
    synth.set_rig(small);
    ADD_FAILURE() << "a rig of another image size was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("side"), std::string::npos) << e.what();
  }
  capture::RigCalibration bad = posed_rig(s.rig, 10, Eigen::Vector3d::Zero());
  bad.front.fx = NAN;
  EXPECT_THROW(synth.set_rig(bad), std::invalid_argument);
  bad = s.rig;
  bad.front.cam_from_head.translation().z() = INFINITY;
  EXPECT_THROW(synth.set_rig(bad), std::invalid_argument);
  EXPECT_EQ(cv::norm(before.image, synth.render(cam).view.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(before.image, synth.render(cam).view.image, cv::NORM_INF), 0.0);
}

// Head tracking: the head in the live frames moved by a pose P, so each live camera sees the
// unmoved mesh as the camera composed with P (capture::posed_camera). With that rig set, the
// synthesizer built on the unmoved head reproduces the moved head's front photo.
TEST(NewView, PosedRigOnTheUnmovedMeshReproducesTheMovedHeadsPhotos) {
  const sim::Head head = sim::make_head(1);
  const capture::RigCalibration rig = sim::nominal_rig(sim::RigOptions{});
  const mesh::TriMesh bare = without_texture(head.mesh);
  Renderer renderer;
  const cv::Mat front0 = renderer.render(head.mesh, rig.front).image,
                side0 = renderer.render(head.mesh, rig.side).image;
  ViewSynthesizer synth(bare, rig, front0, side0);  // the station's start: the head unmoved
  const capture::RigCalibration posed = posed_rig(rig, 10, Eigen::Vector3d(6, -4, 8));
  const RenderResult front = renderer.render(head.mesh, posed.front),
                     side = renderer.render(head.mesh, posed.side);
  synth.set_photos(front.image, side.image);  // the live frames of the moved head
  const double stale = psnr(front.image, synth.render(posed.front).view.image, front.mask);
  synth.set_rig(posed);
  const SynthesisResult r = synth.render(posed.front);
  const double p = psnr(front.image, r.view.image, front.mask);
  std::printf(
      "moved head (yaw 10 deg, t (6, -4, 8) mm), front view: PSNR %.2f dB with the posed "
      "rig, %.2f dB with the old rig\n",
      p, stale);
  EXPECT_GE(p, 30.0);
  EXPECT_LT(stale, p - 5);  // the pose matters
  EXPECT_LT(cv::countNonZero(r.view.mask != front.mask), cv::countNonZero(front.mask) / 100);

  // What the station pays per tracked frame.
  using clock = std::chrono::steady_clock;
  const int n = 30;
  const auto t0 = clock::now();
  for (int k = 0; k < n; ++k)
    synth.set_rig(posed_rig(rig, 10 - 0.3 * k, Eigen::Vector3d(6, -4, 8 - 0.2 * k)));
  const double ms = std::chrono::duration<double, std::milli>(clock::now() - t0).count() / n;
  std::printf("set_rig: %.2f ms per call (%dx%d rig, %zu vertices, %zu triangles)\n", ms,
              rig.front.width, rig.front.height, head.mesh.vertices.size(),
              head.mesh.triangles.size());
}

TEST(NewView, EqualizeGridSamplesTheMappingAndRejectsBadSizes) {
  ColourMatch m;
  m.samples = 100;
  m.mean = {cv::Vec3d(60, 5, 10), cv::Vec3d(40, -5, 20)};
  m.stddev = {cv::Vec3d(10, 4, 4), cv::Vec3d(12, 5, 3)};
  const int n = 5;
  const cv::Mat grid = detail::equalize_grid(m, 1, n);
  ASSERT_EQ(grid.total(), size_t(n * n * n));
  const cv::Mat node(1, 1, CV_8UC3, cv::Scalar(255, 0, 191));  // BGR at grid node (4, 0, 3)
  const cv::Vec3b expected = detail::equalized(node, m, 1).at<cv::Vec3b>(0, 0);
  const cv::Vec3f got = grid.at<cv::Vec3f>(0, (4 * n + 0) * n + 3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k] * 255, expected[k], 1.0);
  m.samples = detail::kMinSamples - 1;  // too few samples: the identity
  const cv::Vec3f same = detail::equalize_grid(m, 0, n).at<cv::Vec3f>(0, (1 * n + 2) * n + 3);
  EXPECT_FLOAT_EQ(same[0], 0.25f);
  EXPECT_FLOAT_EQ(same[1], 0.5f);
  EXPECT_FLOAT_EQ(same[2], 0.75f);
  EXPECT_THROW(detail::equalize_grid(m, 0, 1), std::invalid_argument);
  EXPECT_THROW(detail::equalize_grid(m, 0, 257), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
