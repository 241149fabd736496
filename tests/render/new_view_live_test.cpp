// Texture inheritance with live photos: new photos for the same mesh, and the colour match
// between the photos kept or recomputed.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
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
