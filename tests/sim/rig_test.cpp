#include "sim/rig.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "render/shapes.h"
#include "sim/face_mask.h"
#include "sim/head.h"
#include "sim/scan.h"
#include "sim/sim_folder.h"
#include "sim/truth_json.h"
#include "tests/common/scene_photo.h"
#include "tests/common/test_data.h"

namespace orthoface::sim {
namespace {

// Point on the ellipsoid with semi-axes r in direction d.
Eigen::Vector3d on_ellipsoid(const Eigen::Vector3d& r, Eigen::Vector3d d) {
  d.normalize();
  return d / std::sqrt(d.cwiseQuotient(r).squaredNorm());
}

// Analytic test head: a textured ellipsoid with "landmarks" on its surface.
Head ellipsoid_head() {
  const Eigen::Vector3d r(75, 110, 95);
  Head h;
  h.mesh = render::uv_ellipsoid(Eigen::Vector3d::Zero(), r, 96, 128, 256);
  h.name = "ellipsoid";
  h.landmarks["nose_tip"] = on_ellipsoid(r, {0, 0, 1});
  h.landmarks["eye_left_center"] = on_ellipsoid(r, {0.35, 0.25, 1});
  h.landmarks["eye_right_center"] = on_ellipsoid(r, {-0.35, 0.25, 1});
  h.landmarks["chin"] = on_ellipsoid(r, {0, -0.8, 0.6});
  h.landmarks["forehead_top"] = on_ellipsoid(r, {0, 0.8, 0.6});
  h.landmarks["ear_left_top"] = on_ellipsoid(r, {1, 0.15, -0.05});
  h.landmarks["ear_right_top"] = on_ellipsoid(r, {-1, 0.15, -0.05});
  h.landmarks["back"] = on_ellipsoid(r, {0.1, 0.1, -1});
  return h;
}

// Where the renderer draws head point p: a small camera-facing quad centred on p whose vertex
// colours ramp along the image axes (red along x, green along y); a least-squares fit of pixel
// centre against colour gives the sub-pixel image of p (8-bit colour over ~12 px: ~0.05 px).
Eigen::Vector2d rendered_position(render::Renderer& renderer, const capture::CameraModel& cam,
                                  const Eigen::Vector3d& p) {
  const Eigen::Matrix3d head_from_cam = cam.cam_from_head.linear().transpose();
  const double z = capture::depth(cam, p);
  const double half_mm =
      6.0 * (cam.projection == capture::Projection::Orthographic ? 1.0 : z) / cam.fx;
  mesh::TriMesh quad;
  for (int k = 0; k < 4; ++k) {
    const double sx = (k & 1) ? 1 : -1, sy = (k & 2) ? 1 : -1;
    quad.vertices.push_back(p + half_mm * (sx * head_from_cam.col(0) + sy * head_from_cam.col(1)));
    quad.colors.emplace_back((sx + 1) / 2, (sy + 1) / 2, 1.0);
  }
  quad.triangles = {{0, 1, 3}, {0, 3, 2}};
  render::RenderOptions ro;
  ro.cull_back_faces = false;
  const render::RenderResult r = renderer.render(quad, cam, ro);
  // Regress pixel centre on colour; the centre of the quad has colour 0.5.
  double n = 0;
  Eigen::Vector2d sum_c = Eigen::Vector2d::Zero(), sum_p = Eigen::Vector2d::Zero();
  Eigen::Vector2d scc = Eigen::Vector2d::Zero(), scp = Eigen::Vector2d::Zero();
  for (int row = 0; row < r.mask.rows; ++row)
    for (int col = 0; col < r.mask.cols; ++col) {
      if (!r.mask.at<uchar>(row, col)) continue;
      const cv::Vec3b bgr = r.image.at<cv::Vec3b>(row, col);
      const Eigen::Vector2d c(bgr[2] / 255.0, bgr[1] / 255.0), px(col + 0.5, row + 0.5);
      n += 1;
      sum_c += c;
      sum_p += px;
      scc += c.cwiseProduct(c);
      scp += c.cwiseProduct(px);
    }
  if (n < 10) return Eigen::Vector2d::Constant(NAN);
  Eigen::Vector2d out;
  for (int a = 0; a < 2; ++a) {
    const double slope = (scp[a] - sum_c[a] * sum_p[a] / n) / (scc[a] - sum_c[a] * sum_c[a] / n);
    out[a] = sum_p[a] / n + slope * (0.5 - sum_c[a] / n);
  }
  return out;
}

double max_projection_error(render::Renderer& renderer, const Head& head, const Capture& cap) {
  double worst = 0;
  for (const auto& [name, t] : cap.landmarks) {
    const Eigen::Vector2d f = rendered_position(renderer, cap.true_rig.front, t.xyz_mm);
    const Eigen::Vector2d s = rendered_position(renderer, cap.true_rig.side, t.xyz_mm);
    EXPECT_TRUE(f.allFinite() && s.allFinite()) << name;
    worst = std::max({worst, (f - t.front_px).norm(), (s - t.side_px).norm()});
  }
  (void)head;
  return worst;
}

TEST(RigOptions, RejectsBadValues) {
  auto bad = [](auto edit) {
    RigOptions o;
    edit(o);
    EXPECT_THROW(o.check(), std::invalid_argument);
  };
  bad([](RigOptions& o) { o.width = 0; });
  bad([](RigOptions& o) { o.height = 100000; });
  bad([](RigOptions& o) { o.px_per_mm = 0; });
  bad([](RigOptions& o) { o.focal_px = NAN; });
  bad([](RigOptions& o) { o.distance_mm = 50; });
  bad([](RigOptions& o) { o.front_error.yaw_deg = 46; });
  bad([](RigOptions& o) { o.side_error.offset_mm.x() = INFINITY; });
  bad([](RigOptions& o) { o.ambient = -0.1; });
  bad([](RigOptions& o) { o.light_direction = Eigen::Vector3d::Zero(); });
  bad([](RigOptions& o) { o.noise_sigma = -1; });
  bad([](RigOptions& o) { o.blur_sigma = NAN; });
  bad([](RigOptions& o) { o.background_bgr = cv::Scalar(0, 300, 0); });
  RigOptions tiny;  // degenerate but valid: a 1x1 image
  tiny.width = tiny.height = 1;
  EXPECT_NO_THROW(tiny.check());
}

TEST(Rig, IdealLandmarksLandWhereTheRendererDrawsThemAndOnTheSameRow) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  const Capture cap = simulate_capture(head, {}, renderer);
  const double err = max_projection_error(renderer, head, cap);
  EXPECT_LT(err, 0.5);
  std::cout << "ideal rig: max landmark projection error " << err << " px\n";
  for (const auto& [name, t] : cap.landmarks)
    EXPECT_NEAR(t.front_px.y(), t.side_px.y(), 1e-9) << name;  // seed 004 eq. 1
}

// Visible landmarks away from depth edges lie on the rendered surface: the depth map at their
// pixel agrees with their own depth. Returns how many were checked.
int check_on_rendered_surface(const cv::Mat& depth_mm, const capture::CameraModel& cam,
                              const std::map<std::string, LandmarkTruth>& lms, bool front) {
  int checked = 0;
  for (const auto& [name, t] : lms) {
    const Eigen::Vector2d px = front ? t.front_px : t.side_px;
    if (!(front ? t.visible_front : t.visible_side)) continue;
    const int c = int(px.x()), r = int(px.y());
    if (c < 1 || r < 1 || c + 1 >= depth_mm.cols || r + 1 >= depth_mm.rows) continue;
    double lo = INFINITY, hi = -INFINITY;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        lo = std::min(lo, double(depth_mm.at<float>(r + dr, c + dc)));
        hi = std::max(hi, double(depth_mm.at<float>(r + dr, c + dc)));
      }
    if (!(hi - lo < 3.0)) continue;  // silhouette or crease: the pixel grid decides
    EXPECT_NEAR(depth_mm.at<float>(r, c), capture::depth(cam, t.xyz_mm), 1.5) << name;
    ++checked;
  }
  return checked;
}

TEST(Rig, SimHeadLandmarksLandWhereTheRendererDrawsThem) {
  render::Renderer renderer;
  double worst = 0;
  for (int seed : {0, 1, 2}) {
    const Head head = make_head(seed);
    const Capture cap = simulate_capture(head, {}, renderer);
    ASSERT_EQ(cap.landmarks.size(), head.landmarks.size());
    worst = std::max(worst, max_projection_error(renderer, head, cap));
    for (const auto& [name, t] : cap.landmarks)
      EXPECT_NEAR(t.front_px.y(), t.side_px.y(), 1e-9) << name;  // seed 004 eq. 1
    EXPECT_GE(
        check_on_rendered_surface(cap.front_depth_mm, cap.true_rig.front, cap.landmarks, true), 15);
    EXPECT_GE(check_on_rendered_surface(cap.side_depth_mm, cap.true_rig.side, cap.landmarks, false),
              6);
    // The midline profile faces the side camera; the far eye does not.
    EXPECT_TRUE(cap.landmarks.at("nose_bridge").visible_side);
    EXPECT_TRUE(cap.landmarks.at("eye_left_outer").visible_side);
    EXPECT_FALSE(cap.landmarks.at("eye_right_outer").visible_side);
    EXPECT_TRUE(cap.landmarks.at("eye_right_outer").visible_front);
  }
  std::cout << "sim heads 0-2, ideal rig: max landmark projection error " << worst << " px\n";
  EXPECT_LT(worst, 0.5);
}

TEST(Rig, ScanLandmarksLandWhereTheRendererDrawsThem) {
  const std::string dir = testing::shared_data("lee_perry_smith_head");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/lee_perry_smith_head";
  render::Renderer renderer;
  const Head head = lee_perry_smith_head(dir);
  const Capture cap = simulate_capture(head, {}, renderer);
  const double err = max_projection_error(renderer, head, cap);
  std::cout << "Lee Perry-Smith scan, ideal rig: max landmark projection error " << err << " px\n";
  EXPECT_LT(err, 0.5);
  for (const auto& [name, t] : cap.landmarks)
    EXPECT_NEAR(t.front_px.y(), t.side_px.y(), 1e-9) << name;  // seed 004 eq. 1
  EXPECT_TRUE(cap.landmarks.at("nose_tip").visible_front);
  EXPECT_GT(cv::countNonZero(cap.front_mask), 0.2 * cap.front_mask.total());
}

TEST(Rig, PerspectiveRigWithPoseErrorsStillMatchesTheRenderer) {
  render::Renderer renderer;
  RigOptions o;
  o.kind = RigKind::Perspective;
  o.focal_px = 1500;
  o.distance_mm = 900;
  o.front_error = {1.0, -1.5, 0.8, {3, -2, 5}};
  o.side_error = {-0.7, 1.2, 0.5, {-4, 1, 2}};
  const Head head = ellipsoid_head();
  const Capture cap = simulate_capture(head, o, renderer);
  const double err = max_projection_error(renderer, head, cap);
  std::cout << "perspective rig with pose errors: max landmark projection error " << err << " px\n";
  EXPECT_LT(err, 0.5);
  // The nominal rig is what a station believes; it differs from the true one.
  const Eigen::Vector3d nose = head.landmarks.at("nose_tip");
  EXPECT_GT((capture::project(cap.nominal_rig.front, nose) - cap.landmarks.at("nose_tip").front_px)
                .norm(),
            5.0);
}

TEST(Rig, PoseErrorTurnsTheTrueCameraByTheGivenAngle) {
  RigOptions o;
  o.side_error.yaw_deg = 2.0;
  const auto nominal = nominal_rig(o), truth = true_rig(o);
  const double angle =
      std::acos(capture::view_direction(nominal.side).dot(capture::view_direction(truth.side)));
  EXPECT_NEAR(angle * 180 / M_PI, 2.0, 1e-9);
  EXPECT_TRUE(truth.front.cam_from_head.isApprox(nominal.front.cam_from_head));
  // The head origin stays on the optical axis: projects to the principal point.
  EXPECT_LT((capture::project(truth.side, Eigen::Vector3d::Zero()) -
             Eigen::Vector2d(o.width / 2.0, o.height / 2.0))
                .norm(),
            1e-9);
}

TEST(Rig, VisibilityFollowsTheDepthTest) {
  const Capture cap = simulate_capture(ellipsoid_head(), {});
  const auto& lm = cap.landmarks;
  EXPECT_TRUE(lm.at("nose_tip").visible_front);
  EXPECT_TRUE(lm.at("nose_tip").visible_side);
  EXPECT_TRUE(lm.at("eye_left_center").visible_side);    // the side camera stands at +x
  EXPECT_FALSE(lm.at("eye_right_center").visible_side);  // hidden behind the head
  EXPECT_TRUE(lm.at("ear_left_top").visible_side);
  EXPECT_FALSE(lm.at("ear_right_top").visible_side);
  EXPECT_FALSE(lm.at("back").visible_front);
  // Visible landmarks lie on the rendered surface: the depth map agrees at their pixel.
  for (const auto& [name, t] : lm) {
    if (!t.visible_front) continue;
    const float d = cap.front_depth_mm.at<float>(int(t.front_px.y()), int(t.front_px.x()));
    if (name != "ear_left_top" && name != "ear_right_top") {  // silhouette points: steep depth
      EXPECT_NEAR(d, capture::depth(cap.true_rig.front, t.xyz_mm), 1.0) << name;
    }
  }
}

double background_std(const Capture& cap) {
  cv::Scalar mean, sd;
  cv::Mat bg;
  cv::bitwise_not(cap.front_mask, bg);
  cv::erode(bg, bg, cv::Mat(), cv::Point(-1, -1), 3);
  cv::meanStdDev(cap.front, mean, sd, bg);
  return (sd[0] + sd[1] + sd[2]) / 3;
}

TEST(Rig, NoiseSigmaIsMeasuredBackAndZeroNoiseIsExact) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  RigOptions o;
  o.background_bgr = cv::Scalar(120, 128, 136);
  EXPECT_EQ(background_std(simulate_capture(head, o, renderer)), 0.0);
  for (double sigma : {2.0, 6.0, 15.0}) {
    o.noise_sigma = sigma;
    const Capture cap = simulate_capture(head, o, renderer);
    EXPECT_NEAR(background_std(cap), sigma, 0.1 * sigma) << sigma;
    // The background frame has its own noise draw.
    EXPECT_GT(cv::norm(cap.background_front, cap.front, cv::NORM_L1, ~cap.front_mask), 0.0);
  }
  // Same seed, same noise; another seed, other noise.
  o.noise_sigma = 5;
  const cv::Mat a = simulate_capture(head, o, renderer).front;
  EXPECT_EQ(cv::norm(a, simulate_capture(head, o, renderer).front, cv::NORM_INF), 0.0);
  o.seed = 9;
  EXPECT_GT(cv::norm(a, simulate_capture(head, o, renderer).front, cv::NORM_L1), 0.0);
}

double edge_energy(const cv::Mat& bgr) {
  cv::Mat grey, gx;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::Sobel(grey, gx, CV_32F, 1, 0);
  return cv::norm(gx, cv::NORM_L2);
}

TEST(Rig, BlurSoftensTheSilhouette) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  RigOptions o;
  const double sharp = edge_energy(simulate_capture(head, o, renderer).front);
  o.blur_sigma = 2.0;
  const Capture blurred = simulate_capture(head, o, renderer);
  EXPECT_LT(edge_energy(blurred.front), 0.7 * sharp);
  // Blur does not change the truth masks.
  EXPECT_EQ(cv::countNonZero(blurred.front_mask != simulate_capture(head, {}, renderer).front_mask),
            0);
}

TEST(Rig, ClutteredBackgroundIsBusyDeterministicAndLeavesTheHeadAlone) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  RigOptions o;
  o.background = BackgroundKind::Cluttered;
  o.seed = 3;
  const Capture a = simulate_capture(head, o, renderer);
  EXPECT_GT(background_std(a), 20.0);
  EXPECT_EQ(cv::norm(a.front, simulate_capture(head, o, renderer).front, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.front, a.side, cv::NORM_L1, ~a.front_mask & ~a.side_mask), 0.0);
  const Capture plain = simulate_capture(head, {}, renderer);
  EXPECT_EQ(cv::norm(a.front, plain.front, cv::NORM_INF, a.front_mask), 0.0);
  EXPECT_EQ(cv::norm(a.background_front, background_image(o, 0), cv::NORM_INF), 0.0);  // no noise
  o.seed = 4;
  EXPECT_GT(cv::norm(background_image(o, 0), a.background_front, cv::NORM_L1), 0.0);
}

TEST(Rig, PhotoBackgroundShowsEachCameraItsOwnPartOfTheScene) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  const auto dir = testing::temp_dir("rig_photo");
  RigOptions o;
  o.background = BackgroundKind::Photo;
  o.background_photo = testing::write_scene_photo((dir / "room.png").string(), 4);
  o.seed = 2;
  const Capture a = simulate_capture(head, o, renderer);
  EXPECT_GT(background_std(a), 20.0);
  ASSERT_EQ(a.background_front.size(), cv::Size(o.width, o.height));
  EXPECT_GT(cv::norm(a.background_front, a.background_side, cv::NORM_L1) / a.front.total(), 10.0);
  EXPECT_EQ(cv::norm(a.front, simulate_capture(head, o, renderer).front, cv::NORM_INF), 0.0);
  const Capture plain = simulate_capture(head, {}, renderer);
  EXPECT_EQ(cv::norm(a.front, plain.front, cv::NORM_INF, a.front_mask), 0.0);  // the head alone
  o.seed = 3;  // another seed, another part of the scene
  EXPECT_GT(cv::norm(background_image(o, 0), a.background_front, cv::NORM_L1), 0.0);
  RigOptions no_photo = o;
  no_photo.background_photo.clear();
  EXPECT_THROW(no_photo.check(), std::invalid_argument);
  RigOptions stray;
  stray.background_photo = "room.png";  // a photo without the photo background
  EXPECT_THROW(stray.check(), std::invalid_argument);
  RigOptions missing = o;
  missing.background_photo = (dir / "missing.png").string();
  try {
    background_image(missing, 0);
    ADD_FAILURE() << "a missing photo was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
}

TEST(Rig, LightingScalesTheHead) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  RigOptions o;
  o.ambient = 1.0;
  o.diffuse = 0.0;
  const Capture full = simulate_capture(head, o, renderer);
  o.ambient = 0.5;
  const Capture half = simulate_capture(head, o, renderer);
  const double m_full = cv::mean(full.front, full.front_mask)[1];
  EXPECT_NEAR(cv::mean(half.front, half.front_mask)[1], m_full / 2, 0.02 * m_full);
  // A light from the subject's left (travelling toward -x) brightens the +x half in the front view.
  o.ambient = 0.3;
  o.diffuse = 0.8;
  o.light_direction = Eigen::Vector3d(-1, 0, 0);
  const Capture lit = simulate_capture(head, o, renderer);
  const int mid = o.width / 2;
  const cv::Rect left_half(0, 0, mid, o.height), right_half(mid, 0, o.width - mid, o.height);
  EXPECT_GT(cv::mean(lit.front(right_half), lit.front_mask(right_half))[1],
            1.5 * cv::mean(lit.front(left_half), lit.front_mask(left_half))[1]);
}

TEST(Rig, TrueViewAtYaw0And90ReproducesTheCleanPhotos) {
  render::Renderer renderer;
  const Head head = ellipsoid_head();
  for (RigKind kind : {RigKind::Ideal, RigKind::Perspective}) {
    RigOptions o;
    o.kind = kind;
    const Capture cap = simulate_capture(head, o, renderer);
    const render::RenderResult v0 = true_view(head, o, 0.0, 0.0, renderer);
    const render::RenderResult v90 = true_view(head, o, M_PI / 2, 0.0, renderer);
    EXPECT_LE(cv::norm(v0.image, cap.front, cv::NORM_INF), 1.0);
    EXPECT_LE(cv::norm(v90.image, cap.side, cv::NORM_INF), 1.0);
    EXPECT_EQ(cv::countNonZero(v0.mask != cap.front_mask), 0);
    const render::RenderResult v45 = true_view(head, o, M_PI / 4, 0.2, renderer);
    EXPECT_GT(cv::countNonZero(v45.mask), 1000);
  }
  EXPECT_THROW(true_view(head, {}, NAN, 0.0, renderer), std::invalid_argument);
}

TEST(Rig, RejectsBadInput) {
  render::Renderer renderer;
  Head empty;
  EXPECT_THROW(simulate_capture(empty, {}, renderer), std::invalid_argument);
  RigOptions bad;
  bad.width = 0;
  EXPECT_THROW(simulate_capture(ellipsoid_head(), bad, renderer), std::invalid_argument);
  EXPECT_THROW(nominal_rig(bad), std::invalid_argument);
  EXPECT_THROW(true_rig(bad), std::invalid_argument);
  EXPECT_THROW(background_image({}, 2), std::invalid_argument);
  EXPECT_THROW(degrade(cv::Mat(), {}, 0), std::invalid_argument);
  EXPECT_THROW(degrade(cv::Mat(4, 4, CV_8U), {}, 0), std::invalid_argument);
}

TEST(Rig, TinyImageIsADegenerateButValidCapture) {
  RigOptions o;
  o.width = o.height = 1;
  const Capture cap = simulate_capture(ellipsoid_head(), o);
  EXPECT_EQ(cap.front.size(), cv::Size(1, 1));
  EXPECT_FALSE(cap.landmarks.at("chin").visible_front);  // outside the 1-pixel image
}

TEST(FaceMask, CoversTheFaceNotHairEarsOrNeck) {
  render::Renderer renderer;
  const Head head = make_head(0);
  const Capture cap = simulate_capture(head, {}, renderer);
  ASSERT_FALSE(cap.front_face_mask.empty());
  auto at = [](const cv::Mat& m, const Eigen::Vector2d& px) {
    return m.at<uchar>(int(px.y()), int(px.x()));
  };
  const auto& lm = cap.landmarks;
  EXPECT_EQ(at(cap.front_face_mask, lm.at("nose_tip").front_px), 255);
  EXPECT_EQ(at(cap.front_face_mask, lm.at("eye_right_outer").front_px), 255);
  EXPECT_EQ(at(cap.side_face_mask, lm.at("eye_left_outer").side_px), 255);
  EXPECT_EQ(at(cap.side_face_mask, lm.at("ear_left_tragus").side_px), 0);
  EXPECT_EQ(cv::countNonZero(cap.front_face_mask & ~cap.front_mask), 0);  // inside the head
  const cv::Rect head_box = cv::boundingRect(cap.front_mask);
  const cv::Rect face_box = cv::boundingRect(cap.front_face_mask);
  EXPECT_GT(face_box.y, head_box.y + 20);            // no hair cap
  EXPECT_LT(face_box.br().y, head_box.br().y - 20);  // no neck
  EXPECT_LT(cv::countNonZero(cap.front_face_mask), 0.7 * cv::countNonZero(cap.front_mask));
  // The same mask for a true view comes from true_view_camera.
  const cv::Mat m0 = face_mask(head, true_view_camera({}, 0, 0), renderer);
  EXPECT_EQ(cv::countNonZero(m0 != cap.front_face_mask), 0);
}

TEST(FaceMask, NeedsItsLandmarks) {
  render::Renderer renderer;
  Head head = ellipsoid_head();  // no chin_bottom / tragi: degenerate, capture has no face mask
  EXPECT_FALSE(has_face_landmarks(head));
  EXPECT_TRUE(simulate_capture(head, {}, renderer).front_face_mask.empty());
  EXPECT_THROW(face_vertices(head), std::invalid_argument);
  EXPECT_THROW(true_view_camera({}, INFINITY, 0), std::invalid_argument);
}

TEST(SimulationFolder, WritesEveryFileOrNone) {
  RigOptions o;
  o.width = o.height = 1;  // degenerate: a 1x1 capture still makes a complete folder
  const Head head = ellipsoid_head();
  const Capture cap = simulate_capture(head, o);
  const auto dir = testing::temp_dir("sim_folder");
  write_simulation(dir.string(), head, cap, o);
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(e.path().extension().string().find("tmp"), std::string::npos) << e.path();
    ++files;
  }
  EXPECT_EQ(files, 11);  // 6 images, truth.obj/.mtl/.png, landmarks.json, rig.yaml
  EXPECT_THROW(write_simulation((dir / "missing").string(), head, cap, o), std::runtime_error);
  Capture broken = cap;
  broken.side = cv::Mat();  // cannot be encoded: nothing of the new set may appear
  const auto dir2 = testing::temp_dir("sim_folder_broken");
  EXPECT_THROW(write_simulation(dir2.string(), head, broken, o), std::runtime_error);
  EXPECT_TRUE(std::filesystem::is_empty(dir2));
}

TEST(TruthJson, RoundTrips) {
  RigOptions o;
  o.kind = RigKind::Perspective;
  o.seed = 12;
  o.noise_sigma = 3;
  o.background = BackgroundKind::Cluttered;
  o.front_error = {0.5, -0.25, 1, {1, 2, 3}};
  o.width = 320;
  o.height = 240;
  const Capture cap = simulate_capture(ellipsoid_head(), o);
  const Truth t = make_truth(cap, o, "ellipsoid", "truth.obj");
  const auto dir = testing::temp_dir("truth_json");
  const std::string path = (dir / "landmarks.json").string();
  write_truth_json(t, path);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const Truth b = read_truth_json(path);
  EXPECT_EQ(b.subject, "ellipsoid");
  EXPECT_EQ(b.mesh_file, "truth.obj");
  EXPECT_EQ(b.options.seed, 12u);
  EXPECT_EQ(b.options.width, 320);
  EXPECT_EQ(b.options.kind, RigKind::Perspective);
  EXPECT_EQ(b.options.background, BackgroundKind::Cluttered);
  EXPECT_DOUBLE_EQ(b.options.front_error.pitch_deg, 1.0);
  EXPECT_TRUE(b.true_rig.front.cam_from_head.isApprox(cap.true_rig.front.cam_from_head, 1e-12));
  EXPECT_TRUE(b.nominal_rig.side.cam_from_head.isApprox(cap.nominal_rig.side.cam_from_head, 1e-12));
  ASSERT_EQ(b.landmarks.size(), cap.landmarks.size());
  for (const auto& [name, lt] : cap.landmarks) {
    const LandmarkTruth& r = b.landmarks.at(name);
    EXPECT_LT((r.xyz_mm - lt.xyz_mm).norm(), 1e-9) << name;
    EXPECT_LT((r.front_px - lt.front_px).norm(), 1e-9) << name;
    EXPECT_LT((r.side_px - lt.side_px).norm(), 1e-9) << name;
    EXPECT_EQ(r.visible_front, lt.visible_front) << name;
    EXPECT_EQ(r.visible_side, lt.visible_side) << name;
  }
}

TEST(TruthJson, MalformedFilesThrowNamingTheProblem) {
  const auto dir = testing::temp_dir("truth_json_bad");
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    const auto p = dir / "t.json";
    std::ofstream(p) << text;
    try {
      read_truth_json(p.string());
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("{not json", "not valid JSON");
  expect_error("[]", "format");
  expect_error(R"({"format": "orthoface-truth", "version": 2})", "version");
  expect_error(R"({"format": "orthoface-truth", "version": 1, "subject": 5})", "subject");
  EXPECT_THROW(read_truth_json((dir / "missing.json").string()), std::runtime_error);
  // A valid file with one field damaged.
  RigOptions o;
  o.width = 64;
  o.height = 48;
  const Capture cap = simulate_capture(ellipsoid_head(), o);
  write_truth_json(make_truth(cap, o, "e", "truth.obj"), (dir / "good.json").string());
  std::ifstream f(dir / "good.json");
  std::string good((std::istreambuf_iterator<char>(f)), {});
  const auto at = good.find("\"px_per_mm\"");
  ASSERT_NE(at, std::string::npos);
  expect_error(good.substr(0, at) + "\"px_per_mmm\"" + good.substr(at + 11), "options.px_per_mm");
  EXPECT_THROW(write_truth_json(make_truth(cap, o, "e", "t"), (dir / "no/x.json").string()),
               std::runtime_error);
}

}  // namespace
}  // namespace orthoface::sim

namespace orthoface::sim {
namespace {

TEST(LandmarkHullMask, HoldsTheFaceLandmarksAndNotTheEarsOrTheFrame) {
  const Head head = make_head(1);
  const RigOptions o;
  const capture::RigCalibration rig = nominal_rig(o);
  const cv::Mat mask = landmark_hull_mask(head, rig.front, {o.width, o.height});
  ASSERT_EQ(mask.size(), cv::Size(o.width, o.height));
  auto at = [&](const char* name) {
    const Eigen::Vector2d p = capture::project(rig.front, head.landmarks.at(name));
    return mask.at<uchar>(int(p.y()), int(p.x()));
  };
  EXPECT_EQ(at("nose_tip"), 255);
  EXPECT_EQ(at("eye_left_center"), 255);
  EXPECT_EQ(mask.at<uchar>(0, 0), 0);
  // The face is a small part of the frame, well inside the head's outline.
  const double share = double(cv::countNonZero(mask)) / mask.total();
  EXPECT_GT(share, 0.02);
  EXPECT_LT(share, 0.5);
  // No landmarks (or all off the image): an empty mask of the size asked.
  Head bare = head;
  bare.landmarks.clear();
  EXPECT_EQ(cv::countNonZero(landmark_hull_mask(bare, rig.front, {64, 48})), 0);
}

}  // namespace
}  // namespace orthoface::sim
