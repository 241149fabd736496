// Texture inheritance (seed 004 §6) on scenes whose true views are known: the source photos and
// the truth are renders of the same textured mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "render/equalize.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "render/shapes.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "tests/render/new_view_scene.h"

namespace orthoface::render {
namespace {

using namespace testing;

TEST(NewView, ReproducesTheFrontPhotoAtYawZero) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.source_weights = true;
  const SynthesisResult r = synth.render(s.rig.front, o);
  const cv::Mat front_only = only_from_front(r);
  EXPECT_GT(cv::countNonZero(front_only), 50000);
  EXPECT_GT(psnr(s.front, r.view.image, front_only), 45.0);  // same pixels, same camera
}

// The view blend at a source camera's own viewpoint gives that photo back wherever it sees the
// surface; the seed's pick rule gives part of the front view to the side photo (every point
// facing the side camera more), which is where a depth error shows as a doubled feature.
TEST(NewView, ViewBlendTakesEachPhotoAtItsOwnCamera) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.source_weights = true;
  o.equalize = false;
  for (Blend b : {Blend::View, Blend::Pick}) {
    o.blend = b;
    for (int source = 0; source < 2; ++source) {
      const CameraModel& cam = source == 0 ? s.rig.front : s.rig.side;
      const SynthesisResult r = synth.render(cam, o);
      cv::Mat share;
      cv::extractChannel(r.weights, share, source);
      const int drawn = cv::countNonZero(r.view.mask);
      const cv::Mat alone = (share == 255) & r.view.mask;
      const int own = cv::countNonZero(alone);
      const double photo_psnr = psnr(source == 0 ? s.front : s.side, r.view.image, alone);
      std::printf("%s at source %d: %d of %d pixels from it alone, PSNR %.1f dB\n", blend_name(b),
                  source, own, drawn, photo_psnr);
      if (b == Blend::View) {
        EXPECT_GT(own, drawn * 0.98);  // all but the silhouette's grazing rim
        EXPECT_GT(photo_psnr, 45.0);   // the same pixels through the same camera
      } else {
        EXPECT_LT(own, drawn * 0.9);  // the pick rule hands the outer ring to the other photo
      }
    }
  }
}

// A view near the front camera keeps the front photo on the surface that camera sees at a
// grazing angle (there its samples are hardly stretched, and the side photo would bring its
// registration error in: real pairs at 15 deg showed it as a pale strip along the near cheek);
// the narrowing's power says how near.
TEST(NewView, NearTheFrontCameraItsGrazingSamplesStay) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel turned = capture::turned_camera(s.rig.front, 15, 0, Eigen::Vector3d::Zero());
  auto side_share = [&](double narrowing) {
    SynthesisOptions o;
    o.source_weights = true;
    o.ramp_narrowing = narrowing;
    const SynthesisResult r = synth.render(turned, o);
    cv::Mat side;
    cv::extractChannel(r.weights, side, 1);
    return cv::sum(side)[0] / 255.0;
  };
  const double wide = side_share(64), narrow = side_share(8);
  std::printf("side photo's share at 15 deg: %.0f px (narrowing 64), %.0f px (8)\n", wide, narrow);
  EXPECT_LT(narrow, 0.8 * wide);
  for (double bad : {0.5, 300.0, double(NAN)}) {
    SynthesisOptions o;
    o.ramp_narrowing = bad;
    EXPECT_THROW(synth.render(turned, o), std::invalid_argument) << bad;
  }
}

// Between the cameras the View blend hands the surface the side photo faces over to it sooner
// than view_gain 2 did (at 30 degrees), while near the front camera its own viewpoint's gain keeps
// the front photo's share as it was (at 15 degrees).
TEST(NewView, ViewBlendHandsOverAt30DegreesAndKeepsTheFrontPhotoAt15) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  auto side_share = [&](double yaw, double view_gain, double camera_gain) {
    SynthesisOptions o;
    o.source_weights = true;
    o.view_gain = view_gain;
    o.camera_gain = camera_gain;
    const CameraModel turned = capture::turned_camera(s.rig.front, yaw, 0, Eigen::Vector3d::Zero());
    cv::Mat side;
    cv::extractChannel(synth.render(turned, o).weights, side, 1);
    return cv::sum(side)[0] / 255.0;
  };
  const double at30 = side_share(30, 1, 2), at30_before = side_share(30, 2, 0);
  const double at15 = side_share(15, 1, 2), at15_before = side_share(15, 2, 0),
               at15_no_camera = side_share(15, 1, 0);
  std::printf(
      "side photo's share: 30 deg %.0f px (view_gain 2: %.0f); 15 deg %.0f px (view_gain "
      "2: %.0f, no camera gain: %.0f)\n",
      at30, at30_before, at15, at15_before, at15_no_camera);
  EXPECT_GT(at30, 1.2 * at30_before);
  EXPECT_LT(std::abs(at15 - at15_before), 0.1 * at15_before);
  EXPECT_GT(at15_no_camera, 1.2 * at15);
}

// The neck twists, the body stays: vertices of turn weight 0 are drawn where the body camera
// sees them whatever the view's turn, in the front photo's colours; weight 1 turns with the view.
TEST(NewView, VerticesThatDoNotTurnStayAsTheBodyCameraSeesThem) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const Eigen::Vector3d pivot(0, -40, -10);
  const CameraModel turned = capture::turned_camera(s.rig.front, 20, 0, pivot);
  SynthesisOptions o;
  o.body_camera = s.rig.front;
  o.body_pivot = pivot;
  const SynthesisResult at_front = synth.render(s.rig.front, o);
  const SynthesisResult plain = synth.render(turned, o);  // no weights: the whole mesh turns
  synth.set_turn_weights(std::vector<float>(s.bare.vertices.size(), 0.0f));
  const SynthesisResult stays = synth.render(turned, o);
  // The same silhouette and the front photo's picture as at the front camera...
  EXPECT_LT(cv::countNonZero(stays.view.mask != at_front.view.mask), 200);
  EXPECT_GT(psnr(at_front.view.image, stays.view.image, at_front.view.mask & stays.view.mask),
            35.0);
  // ...where the turned view differs.
  EXPECT_LT(psnr(at_front.view.image, plain.view.image, at_front.view.mask & plain.view.mask),
            30.0);
  synth.set_turn_weights(std::vector<float>(s.bare.vertices.size(), 1.0f));
  EXPECT_EQ(cv::countNonZero(synth.render(turned, o).view.mask != plain.view.mask), 0);
  synth.set_turn_weights({});
  EXPECT_EQ(cv::countNonZero(synth.render(turned, o).view.mask != plain.view.mask), 0);
  // Bad weights and a bad body camera are refused.
  EXPECT_THROW(synth.set_turn_weights({0.5f, 0.5f}), std::invalid_argument);
  EXPECT_THROW(synth.set_turn_weights(std::vector<float>(s.bare.vertices.size(), 1.5f)),
               std::invalid_argument);
  SynthesisOptions bad = o;
  bad.body_camera->width = 0;
  EXPECT_THROW(synth.render(turned, bad), std::invalid_argument);
  bad = o;
  bad.body_pivot.x() = NAN;
  EXPECT_THROW(synth.render(turned, bad), std::invalid_argument);
}

// The same when the view is drawn as the flipped view of its mirror image (the side never
// photographed): the body's vertices still stay where the body camera sees them.
TEST(NewView, VerticesThatDoNotTurnStayInAMirroredView) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  synth.set_mirror_plane(Eigen::Vector4d(1, 0, 0, 0));
  const Eigen::Vector3d pivot(0, -40, -10);
  SynthesisOptions o;
  o.body_camera = s.rig.front;
  o.body_pivot = pivot;
  const SynthesisResult at_front = synth.render(s.rig.front, o);
  int mirrored = 0;
  for (const double yaw : {-30.0, 30.0}) {
    const CameraModel turned = capture::turned_camera(s.rig.front, yaw, 0, pivot);
    if (!synth.mirrors_view(turned, o)) continue;
    ++mirrored;
    synth.set_turn_weights({});
    const SynthesisResult plain = synth.render(turned, o);
    synth.set_turn_weights(std::vector<float>(s.bare.vertices.size(), 0.0f));
    const SynthesisResult stays = synth.render(turned, o);
    EXPECT_LT(cv::countNonZero(stays.view.mask != at_front.view.mask), 200) << yaw;
    EXPECT_GT(psnr(at_front.view.image, stays.view.image, at_front.view.mask & stays.view.mask),
              35.0)
        << yaw;
    EXPECT_LT(psnr(at_front.view.image, plain.view.image, at_front.view.mask & plain.view.mask),
              30.0)
        << yaw;
  }
  EXPECT_EQ(mirrored, 1);
}

TEST(NewView, BlendNamesRoundTripAndBadOnesAreRefused) {
  for (Blend b : {Blend::View, Blend::Pick, Blend::Weighted})
    EXPECT_EQ(parse_blend(blend_name(b)), b);
  EXPECT_THROW(parse_blend("nearest"), std::invalid_argument);
  EXPECT_THROW(parse_blend(""), std::invalid_argument);
  SynthesisOptions o;
  o.view_gain = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
  o.view_gain = NAN;
  EXPECT_THROW(o.check(), std::invalid_argument);
  o = SynthesisOptions{};
  for (double gain : {-1.0, 11.0, double(NAN)}) {
    o.camera_gain = gain;
    EXPECT_THROW(o.check(), std::invalid_argument) << gain;
  }
  o = SynthesisOptions{};
  for (double power : {0.5, 5000.0, double(NAN)}) {
    o.camera_power = power;
    EXPECT_THROW(o.check(), std::invalid_argument) << power;
  }
  o = SynthesisOptions{};
  for (double share : {-0.1, 1.5, double(NAN)}) {
    o.hull_view_share = share;
    EXPECT_THROW(o.check(), std::invalid_argument);
  }
}

// A view a little off the front camera: the head hull's sides, which the front photo sees at a
// grazing angle, take the side photo that faces them sooner than the face does (the full view
// preference painted the front photo's stretched samples over them).
TEST(NewView, HullSidesTakeTheSidePhotoSoonerThanTheFace) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  synth.set_face_vertices(0);  // all hull
  for (double yaw : {15.0, 30.0}) {
    const CameraModel cam = view(s.rig.front, yaw);
    const RenderResult truth = render_once(s.textured, cam);
    SynthesisOptions o;
    o.float_textures = false;
    o.source_weights = true;
    double p[2];
    double side_share[2];
    for (int k = 0; k < 2; ++k) {
      o.hull_view_share = k == 0 ? 1.0 : 0.5;
      const SynthesisResult r = synth.render(cam, o);
      p[k] = psnr(truth.image, r.view.image, truth.mask);
      cv::Mat side;
      cv::extractChannel(r.weights, side, 1);
      side_share[k] = cv::mean(side, r.view.mask)[0] / 255;
    }
    std::printf("ellipsoid hull %.0f deg: PSNR %.2f -> %.2f dB, side photo's share %.3f -> %.3f\n",
                yaw, p[0], p[1], side_share[0], side_share[1]);
    EXPECT_GT(side_share[1], side_share[0] + 0.02);
    EXPECT_GT(p[1], p[0]);
  }
}

// The head hull takes no colour from a photo that sees it far more obliquely than the new view
// does (its samples would be streaks): the photos' shares only fall, somewhere to nothing; the
// face keeps them; at the front camera's own viewpoint nothing changes.
TEST(NewView, HullTakesNoColourAPhotoWouldStretch) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.float_textures = false;
  o.source_weights = true;
  o.fill_unseen = false;
  auto shares = [&](const CameraModel& cam, double max_stretch) {
    o.hull_max_stretch = max_stretch;
    return synth.render(cam, o);
  };
  // Turned 20 deg toward the side the side camera never saw: the front photo alone sees the hull's
  // side there, edge-on.
  const CameraModel cam = view(s.rig.front, -20);
  synth.set_face_vertices(0);  // all hull
  const SynthesisResult free = shares(cam, 0), limited = shares(cam, 4);
  cv::Mat front_free, front_limited, diff;
  cv::extractChannel(free.weights, front_free, 0);
  cv::extractChannel(limited.weights, front_limited, 0);
  cv::subtract(front_free, front_limited, diff, cv::noArray(), CV_32F);
  const cv::Mat drawn = free.view.mask > 0;
  double least, most;
  cv::minMaxLoc(diff, &least, &most, nullptr, nullptr, drawn);
  const int dropped = cv::countNonZero((diff > 100) & drawn);
  std::printf(
      "hull at -20 deg: the front photo's share falls on %d of %d pixels (at most by %.0f)\n",
      dropped, cv::countNonZero(drawn), most);
  EXPECT_GE(least, -1.0);  // it never grows
  EXPECT_GT(most, 200.0);  // somewhere it falls to (nearly) nothing
  EXPECT_GT(dropped, 1000);
  EXPECT_LT(dropped, cv::countNonZero(drawn) / 4);
  // The face is never cut.
  synth.set_face_vertices(-1);
  EXPECT_EQ(cv::norm(shares(cam, 0).view.image, shares(cam, 4).view.image, cv::NORM_INF), 0);
  // The front camera's own view: the front photo stretches nothing.
  synth.set_face_vertices(0);
  const CameraModel front = view(s.rig.front, 0);
  EXPECT_LE(cv::norm(shares(front, 0).view.image, shares(front, 4).view.image, cv::NORM_INF), 1);
  for (double bad : {-1.0, 1.0, 1000.0, double(NAN)}) {
    o.hull_max_stretch = bad;
    EXPECT_THROW(o.check(), std::invalid_argument) << bad;
  }
}

TEST(NewView, FloatingTexturesAlignOnlyTheFaceVertices) {
  // Photos of one ellipsoid, a deeper one as the mesh: the two photos disagree on it, and
  // floating textures move them.
  const Scene s = ellipsoid_scene();
  const mesh::TriMesh deeper =
      without_texture(uv_ellipsoid({0, 0, 0}, {70, 100, 100}, 48, 96, 512));
  ViewSynthesizer synth(deeper, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 40);
  SynthesisOptions still;
  still.float_textures = false;
  const cv::Mat drawn = synth.render(cam, still).view.image;
  const cv::Mat floated = synth.render(cam).view.image;
  EXPECT_GT(cv::norm(floated, drawn, cv::NORM_L1), 1000);
  // No vertex is the face: nothing is aligned, the view stays as drawn (the hull's blend).
  synth.set_face_vertices(0);
  const cv::Mat hull_drawn = synth.render(cam, still).view.image;
  EXPECT_LT(cv::norm(synth.render(cam).view.image, hull_drawn, cv::NORM_INF), 2);
  synth.set_face_vertices(-1);
  EXPECT_EQ(cv::norm(synth.render(cam).view.image, floated, cv::NORM_INF), 0);
  EXPECT_THROW(synth.set_face_vertices(-2), std::invalid_argument);
  EXPECT_THROW(synth.set_face_vertices(int(deeper.vertices.size()) + 1), std::invalid_argument);
}

TEST(NewView, FortyFiveDegreesMatchesTheTrueView) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 45);
  const RenderResult truth = render_once(s.textured, cam);
  for (Blend b : {Blend::View, Blend::Pick, Blend::Weighted}) {
    SynthesisOptions o;
    o.blend = b;
    const RenderResult r = synth.render(cam, o).view;
    EXPECT_EQ(cv::countNonZero(r.mask != truth.mask), 0);
    const double p = psnr(truth.image, r.image, truth.mask),
                 q = ssim(truth.image, r.image, truth.mask);
    std::printf("ellipsoid 45 deg %s: PSNR %.2f dB SSIM %.4f\n", blend_name(b), p, q);
    EXPECT_GT(p, 36.0);
    EXPECT_GT(q, 0.98);
  }
}

TEST(NewView, PerspectiveRigMatchesTheTrueView) {
  CameraModel k;
  k.projection = capture::Projection::Perspective;
  k.fx = k.fy = 1000;
  capture::RigCalibration rig{view(k, 0, 0, 700), view(k, 90, 0, 700), "test"};
  const Scene s = make_scene(uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 48, 96, 512), rig);
  const CameraModel cam = view(k, 30, 10, 650);
  const RenderResult truth = render_once(s.textured, cam);
  const RenderResult r = synthesize_view(s.bare, s.rig, s.front, s.side, cam).view;
  const double p = psnr(truth.image, r.image, truth.mask);
  std::printf("perspective rig, yaw 30 pitch 10: PSNR %.2f dB\n", p);
  EXPECT_GT(p, 29.0);
}

TEST(NewView, OccludedPointsNeverTakeColourFromTheHiddenPhoto) {
  // A green sphere with a red ball in front of it (toward the front camera).
  mesh::TriMesh big = uv_ellipsoid({0, 0, 0}, {60, 60, 60}, 32, 64);
  const mesh::TriMesh ball = uv_ellipsoid({0, 0, 95}, {20, 20, 20}, 16, 32);
  big.colors.assign(big.vertices.size(), {0, 1, 0});
  const int offset = int(big.vertices.size());
  for (const auto& v : ball.vertices) big.vertices.push_back(v), big.colors.push_back({1, 0, 0});
  for (const auto& t : ball.triangles)
    big.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const Scene s = make_scene(big, capture::ideal_rig(640, 480, 2.0));
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 60);
  SynthesisOptions o;
  o.source_weights = true;
  const SynthesisResult r = synth.render(cam, o);
  const cv::Mat zfront = synth.source_depth(0);
  int hidden = 0;
  for (int row = 0; row < cam.height; ++row)
    for (int col = 0; col < cam.width; ++col) {
      if (!r.view.mask.at<uchar>(row, col)) continue;
      const Eigen::Vector3d p = unproject(cam, col, row, r.view.depth_mm.at<float>(row, col));
      if (p.norm() > 61) continue;  // on the ball
      const Eigen::Vector2d u = capture::project(s.rig.front, p);
      const double z = capture::depth(s.rig.front, p);
      bool clearly_hidden = true;  // every front depth within 3 px is > 5 mm in front of p
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          const int c = int(u.x()) + dx, rr = int(u.y()) + dy;
          clearly_hidden = clearly_hidden && zfront.at<float>(rr, c) < z - 5;
        }
      if (!clearly_hidden) continue;
      ++hidden;
      ASSERT_EQ(r.weights.at<cv::Vec3b>(row, col)[0], 0) << col << "," << row;
      if (r.weights.at<cv::Vec3b>(row, col)[1] == 255) {  // all from the side photo: green
        ASSERT_LT(r.view.image.at<cv::Vec3b>(row, col)[2], 30) << "red at " << col << "," << row;
      }
    }
  EXPECT_GT(hidden, 300);
}

TEST(NewView, WeightedBlendFollowsTheCosineWeights) {
  const Scene s = make_scene(uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 48, 96, 256),
                             capture::ideal_rig(400, 400, 2.0));
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 30);
  SynthesisOptions o;
  o.blend = Blend::Weighted;
  o.source_weights = true;
  const SynthesisResult r = synth.render(cam, o);
  int checked = 0;
  for (int row = 0; row < cam.height; row += 3)
    for (int col = 0; col < cam.width; col += 3) {
      if (!r.view.mask.at<uchar>(row, col)) continue;
      const Eigen::Vector3d n =
          unproject(cam, col, row, r.view.depth_mm.at<float>(row, col)).normalized();
      const double c0 = n.z(), c1 = n.x();  // facing the front (+z) and side (+x) cameras
      if (c0 < 0.3 || c1 < 0.3) continue;   // faceting moves small cosines a lot
      const double want = c0 * c0 / (c0 * c0 + c1 * c1);
      EXPECT_NEAR(r.weights.at<cv::Vec3b>(row, col)[0], 255 * want, 6) << col << "," << row;
      ++checked;
    }
  EXPECT_GT(checked, 500);
}

TEST(NewView, PickSwitchesAtFortyFiveDegreesWithAFeatheredSeam) {
  const Scene s = make_scene(uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 48, 96, 256),
                             capture::ideal_rig(400, 400, 2.0));
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 45);
  for (double feather : {0.0, 8.0}) {
    SynthesisOptions o;
    o.feather_deg = feather;
    o.source_weights = true;
    const SynthesisResult r = synth.render(cam, o);
    const double band = std::sqrt(2.0) * feather * M_PI / 180;
    int blended = 0, checked = 0;
    for (int row = 0; row < cam.height; row += 2)
      for (int col = 0; col < cam.width; col += 2) {
        if (!r.view.mask.at<uchar>(row, col)) continue;
        const Eigen::Vector3d n =
            unproject(cam, col, row, r.view.depth_mm.at<float>(row, col)).normalized();
        if (n.z() < 0.15 || n.x() < 0.15) continue;
        const double d = n.z() - n.x();  // cos(front) - cos(side)
        const int w = r.weights.at<cv::Vec3b>(row, col)[0];
        if (d > band + 0.01) {
          EXPECT_EQ(w, 255) << col << "," << row;
        }
        if (d < -band - 0.01) {
          EXPECT_EQ(w, 0) << col << "," << row;
        }
        blended += w > 10 && w < 245;
        ++checked;
      }
    EXPECT_GT(checked, 1000);
    if (feather == 0)
      EXPECT_LT(blended, 40);  // only the pixels straddling the switch
    else
      EXPECT_GT(blended, 200);
  }
}

TEST(NewView, SurfaceNoPhotoSeesTakesTheFillColourOrItsSurroundings) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, -135);  // from behind on the far side: no photo
  SynthesisOptions o;
  o.source_weights = true;
  o.fill_unseen = false;
  const SynthesisResult r = synth.render(cam, o);
  const int c = cam.width / 2, row = cam.height / 2;
  ASSERT_EQ(r.view.mask.at<uchar>(row, c), 255);
  EXPECT_EQ(r.weights.at<cv::Vec3b>(row, c)[2], 255);
  const cv::Vec3b fill = synth.colour_match().fill;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.view.image.at<cv::Vec3b>(row, c)[k], fill[k], 1);
  // Filled from the surroundings (the default), the unseen pixels take the seen surface's
  // colours: each one nearer the mean of the seen pixels than the flat fill is.
  o.fill_unseen = true;
  const SynthesisResult f = synth.render(cam, o);
  cv::Mat unseen, seen;
  cv::extractChannel(f.weights, unseen, 2);
  seen = (unseen < 26) & (f.view.mask > 0);
  unseen = (unseen == 255) & (f.view.mask > 0);
  ASSERT_GT(cv::countNonZero(seen), 100);
  ASSERT_GT(cv::countNonZero(unseen), 100);
  const cv::Scalar seen_mean = cv::mean(f.view.image, seen);
  const cv::Scalar filled_mean = cv::mean(f.view.image, unseen);
  const cv::Scalar flat(fill[0], fill[1], fill[2]);
  EXPECT_LT(cv::norm(filled_mean - seen_mean), 0.5 * cv::norm(flat - seen_mean))
      << "seen " << seen_mean << " filled " << filled_mean << " flat " << flat;
}

TEST(NewView, EqualisationRemovesABrightnessStepBetweenThePhotos) {
  mesh::TriMesh ball = uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 32, 64);
  ball.colors.assign(ball.vertices.size(), {0.8, 0.6, 0.5});
  Scene s = make_scene(ball, capture::ideal_rig(400, 400, 2.0));
  s.side.convertTo(s.side, CV_8U, 0.6, 10);  // a darker, differently exposed side camera
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  EXPECT_GT(synth.colour_match().samples, 100);
  EXPECT_GT(synth.colour_match().mean[0][0], synth.colour_match().mean[1][0] + 10);  // L
  const CameraModel cam = view(s.rig.front, 45);
  double step[2];
  for (int eq = 0; eq < 2; ++eq) {
    SynthesisOptions o;
    o.equalize = eq == 1;
    o.feather_deg = 0;
    o.source_weights = true;
    const SynthesisResult r = synth.render(cam, o);
    cv::Mat w0;
    cv::extractChannel(r.weights, w0, 0);
    const cv::Scalar from_front = cv::mean(r.view.image, (w0 == 255) & r.view.mask);
    const cv::Scalar from_side = cv::mean(r.view.image, (w0 == 0) & r.view.mask);
    step[eq] = cv::norm(from_front - from_side);
  }
  std::printf("colour step between sources: raw %.1f, equalised %.1f\n", step[0], step[1]);
  EXPECT_GT(step[0], 30);
  EXPECT_LT(step[1], 4);
}

// Two identical cameras, but a dark band (hair, a shadow: pairs that are not the same surface)
// over a third of the ball in the side photo: the equalisation stays the identity on the rest
// (the median of the pairs' differences), where matching the means brightened the side photo by
// the band's pull.
TEST(NewView, EqualisationIgnoresPairsThatAreNotTheSameSurface) {
  mesh::TriMesh ball = uv_ellipsoid({0, 0, 0}, {80, 80, 80}, 32, 64);
  ball.colors.assign(ball.vertices.size(), {0.8, 0.6, 0.5});
  Scene s = make_scene(ball, capture::ideal_rig(400, 400, 2.0));
  const cv::Mat clean = s.side.clone();
  cv::rectangle(s.side, cv::Rect(0, 0, 400, 160), cv::Scalar(25, 30, 40), cv::FILLED);
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  ASSERT_GT(synth.colour_match().samples, 100);
  const cv::Mat mapped = detail::equalized(s.side, synth.colour_match(), 1);
  const cv::Rect rest(0, 200, 400, 200);  // below the band, the ball's lower half
  cv::Mat on_ball;
  cv::cvtColor(clean(rest), on_ball, cv::COLOR_BGR2GRAY);
  on_ball = on_ball > 20;
  ASSERT_GT(cv::countNonZero(on_ball), 5000);
  const cv::Scalar was = cv::mean(clean(rest), on_ball), now = cv::mean(mapped(rest), on_ball);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(now[k], was[k], 4.0) << "channel " << k;
}

TEST(NewView, WithoutDepthTheImageAndMaskAreTheSame) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 40, 10);
  SynthesisOptions o;
  o.background = cv::Scalar(10, 200, 30);
  const RenderResult full = synth.render(cam, o).view;
  o.depth = false;
  const RenderResult lean = synth.render(cam, o).view;
  EXPECT_TRUE(lean.depth_mm.empty());
  ASSERT_FALSE(full.depth_mm.empty());
  EXPECT_GT(cv::countNonZero(full.mask), 50000);
  EXPECT_EQ(cv::countNonZero(full.mask != lean.mask), 0);
  EXPECT_EQ(cv::norm(full.image, lean.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(lean.image.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 200, 30));
}

TEST(NewView, MeshBehindThePerspectiveViewGivesAnEmptyImage) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  CameraModel k;
  k.projection = capture::Projection::Perspective;
  k.fx = k.fy = 500;
  CameraModel cam = view(k, 0, 0, 600);
  cam.cam_from_head =
      Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()) * cam.cam_from_head;  // look away
  SynthesisOptions o;
  o.background = cv::Scalar(1, 2, 3);
  const SynthesisResult r = synth.render(cam, o);
  EXPECT_EQ(cv::countNonZero(r.view.mask), 0);
  EXPECT_EQ(r.view.image.at<cv::Vec3b>(10, 10), cv::Vec3b(1, 2, 3));
}

TEST(NewView, BadInputsThrow) {
  const Scene s = ellipsoid_scene();
  cv::Mat small;
  cv::resize(s.side, small, cv::Size(320, 240));
  EXPECT_THROW(ViewSynthesizer(s.bare, s.rig, s.front, small), std::invalid_argument);
  EXPECT_THROW(ViewSynthesizer(s.bare, s.rig, cv::Mat(), s.side), std::invalid_argument);
  cv::Mat f32;
  s.front.convertTo(f32, CV_32F);
  EXPECT_THROW(ViewSynthesizer(s.bare, s.rig, f32, s.side), std::invalid_argument);
  EXPECT_THROW(ViewSynthesizer(mesh::TriMesh{}, s.rig, s.front, s.side), std::invalid_argument);
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  CameraModel cam = s.rig.front;
  cam.width = 0;
  EXPECT_THROW(synth.render(cam), std::invalid_argument);
  cam.width = 100000;
  EXPECT_THROW(synth.render(cam), std::invalid_argument);
  SynthesisOptions o;
  o.feather_deg = 90;
  EXPECT_THROW(synth.render(s.rig.front, o), std::invalid_argument);
  o = {};
  o.weighted_power = 0;
  EXPECT_THROW(synth.render(s.rig.front, o), std::invalid_argument);
  for (int bands : {0, 13}) {
    o = {};
    o.blend_bands = bands;
    EXPECT_THROW(synth.render(s.rig.front, o), std::invalid_argument) << bands;
  }
  EXPECT_THROW(synth.source_depth(2), std::invalid_argument);
  EXPECT_THROW(synth.set_photos(s.front, small), std::invalid_argument);
  EXPECT_NO_THROW(synth.render(s.rig.front));  // still usable
}

TEST(NewView, SidePhotoFromTheRightTexturesTheRightSide) {
  capture::RigCalibration taken = capture::ideal_rig(640, 480, 2.0);
  taken.side = capture::photo_rig(taken, false).side;
  const Scene s = make_scene(uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 48, 96, 512), taken);
  const CameraModel cam = view(s.rig.front, -45);
  const RenderResult truth = render_once(s.textured, cam);
  const RenderResult r = synthesize_view(s.bare, s.rig, s.front, s.side, cam).view;
  EXPECT_GT(psnr(truth.image, r.image, truth.mask), 36.0);
}

// A photo pixel outside its subject mask never gives colour: with an empty side mask the side
// photo's weight is zero everywhere, the front photo and the fill take over.
TEST(NewView, PhotoMasksKeepColourFromOutsideTheSubject) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.source_weights = true;
  const CameraModel cam = view(s.rig.front, 70);
  cv::Mat side_weight;
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_GT(cv::countNonZero(side_weight), 10000);
  synth.set_photo_masks({}, cv::Mat::zeros(s.side.size(), CV_8U));
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_EQ(cv::countNonZero(side_weight), 0);
  synth.set_photos(s.front, s.side);  // the masks stay
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_EQ(cv::countNonZero(side_weight), 0);
  synth.set_photo_masks({}, {});  // back to the whole photo
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_GT(cv::countNonZero(side_weight), 10000);
  EXPECT_THROW(synth.set_photo_masks(cv::Mat::zeros(10, 10, CV_8U), {}), std::invalid_argument);
  EXPECT_THROW(synth.set_photo_masks({}, cv::Mat::zeros(s.side.size(), CV_8UC3)),
               std::invalid_argument);
  // New photos and masks in one call (a live frame): the same as the two calls.
  synth.set_photos(s.front, s.side, cv::Mat(), cv::Mat::zeros(s.side.size(), CV_8U));
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_EQ(cv::countNonZero(side_weight), 0);
  // A bad mask changes nothing: the side photo still gives no colour, the photos stay.
  EXPECT_THROW(synth.set_photos(s.front, s.side, cv::Mat::zeros(10, 10, CV_8U), cv::Mat()),
               std::invalid_argument);
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_EQ(cv::countNonZero(side_weight), 0);
  synth.set_photos(s.front, s.side, cv::Mat(), cv::Mat());
  cv::extractChannel(synth.render(cam, o).weights, side_weight, 1);
  EXPECT_GT(cv::countNonZero(side_weight), 10000);
}

// Triangles sorted out as one photo alone or unoccluded are drawn by cheaper programs: the
// image and the source weights must be the very same as with the full test everywhere, for both
// blends, both rigs, many views, and with a subject mask on the side photo.
TEST(NewView, SkippingTheOcclusionTestWhereItCannotFailChangesNoPixel) {
  sim::HeadOptions ho;
  ho.target_triangles = 4000;
  const sim::Head head = sim::make_head(sim::head_params(3), ho);
  for (const capture::RigCalibration& rig :
       {capture::ideal_rig(640, 480, 1.4), sim::true_rig(sim::RigOptions{})}) {
    const Scene s = make_scene(head.mesh, rig);
    ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
    for (int masked = 0; masked < 2; ++masked) {
      if (masked) {
        cv::Mat side_mask(s.side.size(), CV_8U, cv::Scalar(255));
        side_mask.colRange(0, side_mask.cols / 2 - 20).setTo(0);
        synth.set_photo_masks({}, side_mask);
      }
      for (Blend b : {Blend::View, Blend::Pick, Blend::Weighted})
        for (double yaw : {-30.0, 0.0, 20.0, 45.0, 70.0}) {
          SynthesisOptions fast, full;
          fast.blend = full.blend = b;
          fast.float_textures = full.float_textures = false;  // the sorted path
          fast.source_weights = full.source_weights = true;
          full.skip_unoccluded = false;
          const CameraModel cam = view(rig.front, yaw, 10);
          const SynthesisResult a = synth.render(cam, fast), c = synth.render(cam, full);
          ASSERT_GT(cv::countNonZero(a.view.mask), 20000);
          // Most triangles take a cheaper program; without sorting, none does.
          EXPECT_GT(a.triangles_one_photo + a.triangles_untested,
                    int(head.mesh.triangles.size()) / 2);
          EXPECT_GT(a.triangles_one_photo, 0);
          EXPECT_EQ(c.triangles_one_photo + c.triangles_untested, 0);
          EXPECT_EQ(cv::norm(a.view.image, c.view.image, cv::NORM_INF), 0.0)
              << "yaw " << yaw << " masked " << masked << " weighted " << int(b);
          EXPECT_EQ(cv::norm(a.weights, c.weights, cv::NORM_INF), 0.0);
        }
    }
  }
}

}  // namespace
}  // namespace orthoface::render

namespace orthoface::render {
namespace {

// A simulated face (sim/): with its true geometry, the synthesized 45-degree view must match
// the true render closely inside the face mask; this bounds what the reconstruction can reach.
TEST(NewView, SimHeadFortyFiveDegreesWithTheTrueMesh) {
  const sim::Head head = sim::make_head(1);
  const Scene s = make_scene(head.mesh, capture::ideal_rig(640, 480, 1.6));
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  const CameraModel cam = view(s.rig.front, 45);
  const RenderResult truth = render_once(head.mesh, cam);
  const RenderResult r = synth.render(cam).view;
  const double p = psnr(truth.image, r.image, truth.mask),
               q = ssim(truth.image, r.image, truth.mask);
  std::printf("sim head seed 1, 45 deg, true mesh: PSNR %.2f dB SSIM %.4f\n", p, q);
  EXPECT_GT(p, 38.0);
  EXPECT_GT(q, 0.96);
}

}  // namespace
}  // namespace orthoface::render

namespace orthoface::render {
namespace {

// The side never photographed, from the side photo's mirror image: on a symmetric ellipsoid the
// view from the side camera's mirror-image viewpoint is the side photo flipped left to right.
// Both mirror modes: the side photo's mirror image as a texture, and the whole mirrored view.
class NewViewMirror : public ::testing::TestWithParam<UnseenSide> {};

TEST_P(NewViewMirror, MirroredSidePhotoColoursTheSideNeverPhotographed) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.source_weights = true;
  o.float_textures = false;
  o.unseen = GetParam();
  const double far_side = -90 * capture::photographed_side_sign(s.rig);
  const CameraModel cam = view(s.rig.front, far_side);
  auto side_share = [](const SynthesisResult& r) {
    cv::Mat share;
    cv::extractChannel(r.weights, share, 1);
    return cv::mean(share, r.view.mask)[0] / 255;
  };
  const SynthesisResult plain = synth.render(cam, o);
  EXPECT_LT(side_share(plain), 0.01);  // the side camera cannot see this side
  synth.set_mirror_plane(Eigen::Vector4d(1, 0, 0, 0));
  const SynthesisResult mirrored = synth.render(cam, o);
  EXPECT_GT(side_share(mirrored), 0.9);
  cv::Mat flipped, inner;
  cv::flip(s.side, flipped, 1);
  cv::erode(mirrored.view.mask, inner, cv::Mat(), cv::Point(-1, -1), 4);
  EXPECT_GT(psnr(flipped, mirrored.view.image, inner), 28.0);
  // The photographed side is unchanged by the mirror.
  const CameraModel near = view(s.rig.front, -far_side / 2);
  synth.set_mirror_plane(std::nullopt);
  const SynthesisResult a = synth.render(near, o);
  synth.set_mirror_plane(Eigen::Vector4d(1, 0, 0, 0));
  const SynthesisResult b = synth.render(near, o);
  EXPECT_GT(psnr(a.view.image, b.view.image, a.view.mask), 45.0);
}

INSTANTIATE_TEST_SUITE_P(Modes, NewViewMirror,
                         ::testing::Values(UnseenSide::MirrorTexture, UnseenSide::MirrorView),
                         [](const auto& info) {
                           return std::string(unseen_side_name(info.param));
                         });

// MirrorView draws a view turned toward the side never photographed by at least
// mirror_view_from_deg as its mirror image's view flipped; nearer the front camera, or with
// another mode or no plane, the view is drawn as it is.
TEST(NewView, MirrorViewSwitchesAtItsAngleAndIsTheFlippedOppositeView) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  SynthesisOptions o;
  o.float_textures = false;
  const double far_sign = -capture::photographed_side_sign(s.rig);
  const CameraModel far30 = view(s.rig.front, 30 * far_sign),
                    far10 = view(s.rig.front, 10 * far_sign),
                    near30 = view(s.rig.front, -30 * far_sign);
  EXPECT_FALSE(synth.mirrors_view(far30, o));  // no plane yet
  synth.set_mirror_plane(Eigen::Vector4d(1, 0, 0, 0));
  EXPECT_TRUE(synth.mirrors_view(far30, o));
  EXPECT_FALSE(synth.mirrors_view(far10, o));   // below 20 deg
  EXPECT_FALSE(synth.mirrors_view(near30, o));  // the photographed side
  o.mirror_view_from_deg = 5;
  EXPECT_TRUE(synth.mirrors_view(far10, o));
  o.mirror_view_from_deg = 20;
  SynthesisOptions front = o;
  front.unseen = UnseenSide::Front;
  EXPECT_FALSE(synth.mirrors_view(far30, front));
  const SynthesisResult mirrored = synth.render(far30, o);
  const SynthesisResult opposite =
      synth.render(capture::reflected(far30, Eigen::Vector4d(1, 0, 0, 0)), front);
  cv::Mat flipped, flipped_mask;
  cv::flip(opposite.view.image, flipped, 1);
  cv::flip(opposite.view.mask, flipped_mask, 1);
  EXPECT_EQ(cv::countNonZero(flipped_mask != mirrored.view.mask), 0);
  EXPECT_GT(psnr(flipped, mirrored.view.image, mirrored.view.mask), 60.0);
  // The front photo alone differs on the far side (it sees it at a grazing angle).
  const SynthesisResult plain = synth.render(far30, front);
  EXPECT_GT(cv::norm(plain.view.image, mirrored.view.image, cv::NORM_L1), 0.0);
}

TEST(NewView, UnseenSideNamesRoundTripAndBadOnesAreRefused) {
  for (UnseenSide u : {UnseenSide::MirrorView, UnseenSide::MirrorTexture, UnseenSide::Front})
    EXPECT_EQ(parse_unseen_side(unseen_side_name(u)), u);
  EXPECT_THROW(parse_unseen_side("mirror"), std::invalid_argument);
  EXPECT_THROW(parse_unseen_side(""), std::invalid_argument);
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  for (double bad : {-1.0, 181.0, double(NAN)}) {
    SynthesisOptions o;
    o.mirror_view_from_deg = bad;
    EXPECT_THROW(synth.render(s.rig.front, o), std::invalid_argument) << bad;
  }
}

TEST(NewView, MirrorPlaneMustBeAUnitNormal) {
  const Scene s = ellipsoid_scene();
  ViewSynthesizer synth(s.bare, s.rig, s.front, s.side);
  EXPECT_THROW(synth.set_mirror_plane(Eigen::Vector4d(0, 0, 0, 0)), std::invalid_argument);
  EXPECT_THROW(synth.set_mirror_plane(Eigen::Vector4d(NAN, 0, 0, 1)), std::invalid_argument);
  EXPECT_NO_THROW(synth.set_mirror_plane(std::nullopt));
}

}  // namespace
}  // namespace orthoface::render
