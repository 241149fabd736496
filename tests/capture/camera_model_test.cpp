#include "capture/camera_model.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "tests/capture/same_camera.h"
#include "tests/common/test_data.h"

namespace orthoface::capture {
namespace {

namespace fs = std::filesystem;
using orthoface::testing::expect_same_camera;

std::string bad_input(const std::string& name) {
  return std::string(ORTHOFACE_SOURCE_DIR) + "/tests/data/bad_inputs/" + name;
}

CameraModel perspective_intrinsics() {
  CameraModel c;
  c.projection = Projection::Perspective;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 1600.0;
  c.cx = 320.0;
  c.cy = 240.0;
  return c;
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
}

// A valid rig file's text with one line replaced, for the malformed-field tests.
std::string valid_rig_text(const fs::path& dir) {
  const fs::path p = dir / "valid.yaml";
  write_rig(ideal_rig(640, 480, 2.0), p.string());
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(CameraAt, FrontCameraSeesPlusXOnImageRightAndUpAsImageUp) {
  const RigCalibration rig = ideal_rig(640, 480, 2.0);
  const Eigen::Vector2d o = project(rig.front, Eigen::Vector3d::Zero());
  EXPECT_NEAR(o.x(), 320.0, 1e-9);
  EXPECT_NEAR(o.y(), 240.0, 1e-9);
  const Eigen::Vector2d px = project(rig.front, Eigen::Vector3d(10, 0, 0));
  EXPECT_NEAR(px.x(), 340.0, 1e-9);  // +x (subject's left) on the image right
  const Eigen::Vector2d py = project(rig.front, Eigen::Vector3d(0, 10, 0));
  EXPECT_NEAR(py.y(), 220.0, 1e-9);  // +y up = smaller row
  // Depth along the view: the face (+z) is nearer the front camera.
  EXPECT_LT(depth(rig.front, Eigen::Vector3d(0, 0, 50)), depth(rig.front, Eigen::Vector3d::Zero()));
  EXPECT_TRUE(view_direction(rig.front).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
}

TEST(CameraAt, SideCameraSeesTheFaceOnImageLeft) {
  const RigCalibration rig = ideal_rig(640, 480, 2.0);
  const Eigen::Vector2d nose = project(rig.side, Eigen::Vector3d(0, 0, 100));
  EXPECT_NEAR(nose.x(), 120.0, 1e-9);  // +z toward the image left
  EXPECT_NEAR(nose.y(), 240.0, 1e-9);
  EXPECT_TRUE(view_direction(rig.side).isApprox(Eigen::Vector3d(-1, 0, 0), 1e-12));
  // The subject's left ear (+x) is nearer the side camera than the right ear.
  EXPECT_LT(depth(rig.side, Eigen::Vector3d(70, 0, 0)),
            depth(rig.side, Eigen::Vector3d(-70, 0, 0)));
}

// seed 004 eq. 1: in the ideal rig the front column gives x, the side column gives z, and a
// point's row is the same in both images.
TEST(IdealRig, EveryPointHasTheSameRowInBothViewsAndEq1RecoversIt) {
  const double s = 1.7;
  const RigCalibration rig = ideal_rig(800, 600, s);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-150.0, 150.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const Eigen::Vector2d f = project(rig.front, p), q = project(rig.side, p);
    ASSERT_NEAR(f.y(), q.y(), 1e-9);
    const Eigen::Vector3d back((f.x() - 400.0) / s, (300.0 - f.y()) / s, (400.0 - q.x()) / s);
    ASSERT_LT((back - p).norm(), 1e-9);
  }
}

TEST(CameraAt, YawAndPitchMoveTheCameraAsDocumented) {
  const CameraModel base = perspective_intrinsics();
  const CameraModel c45 = camera_at(base, M_PI / 4, 0.0, 1000.0);
  const Eigen::Vector3d centre = c45.cam_from_head.inverse().translation();
  EXPECT_TRUE(centre.isApprox(Eigen::Vector3d(std::sqrt(0.5), 0, std::sqrt(0.5)) * 1000.0, 1e-9));
  const Eigen::Vector2d o = project(c45, Eigen::Vector3d::Zero());
  EXPECT_NEAR(o.x(), 320.0, 1e-9);
  EXPECT_NEAR(o.y(), 240.0, 1e-9);
  // Pitch > 0 looks from above: the camera stands at +y and the top of the head is nearer.
  const CameraModel above = camera_at(base, 0.0, 0.3, 1000.0);
  EXPECT_GT(above.cam_from_head.inverse().translation().y(), 0.0);
  EXPECT_LT(depth(above, Eigen::Vector3d(0, 100, 0)), depth(above, Eigen::Vector3d(0, -100, 0)));
  // Head +y still maps to image up.
  EXPECT_LT(project(above, Eigen::Vector3d(0, 50, 0)).y(), 240.0);
}

TEST(TurnedCamera, TurnsAboutThePivotAndIsTheCameraItselfAtZero) {
  const CameraModel base = camera_at(perspective_intrinsics(), 0.0, 0.0, 1000.0);
  const Eigen::Vector3d pivot(5, -60, -80);
  const CameraModel same = turned_camera(base, 0, 0, pivot);
  EXPECT_TRUE(same.cam_from_head.isApprox(base.cam_from_head, 1e-12));
  // The pivot stays where it was in the image; a point in front of it swings toward image left
  // for yaw > 0 (the camera moves to +x, as camera_at's).
  const CameraModel turned = turned_camera(base, 40, 0, pivot);
  EXPECT_LT((project(turned, pivot) - project(base, pivot)).norm(), 1e-9);
  const Eigen::Vector3d nose(5, -60, 40);
  EXPECT_LT(project(turned, nose).x(), project(base, nose).x() - 10);
  // About the origin it is camera_at itself.
  const CameraModel at = camera_at(perspective_intrinsics(), 40 * M_PI / 180, 0.2, 1000.0);
  const CameraModel t0 = turned_camera(base, 40, 0.2 * 180 / M_PI, Eigen::Vector3d::Zero());
  EXPECT_TRUE(t0.cam_from_head.isApprox(at.cam_from_head, 1e-9));
}

TEST(TurnedCamera, NonFiniteInputIsRefused) {
  const CameraModel base = perspective_intrinsics();
  EXPECT_THROW(turned_camera(base, NAN, 0, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(turned_camera(base, 0, INFINITY, Eigen::Vector3d::Zero()), std::invalid_argument);
  EXPECT_THROW(turned_camera(base, 0, 0, Eigen::Vector3d(0, NAN, 0)), std::invalid_argument);
}

TEST(PosedCamera, TheIdentityPoseGivesTheCameraBack) {
  const CameraModel base = camera_at(perspective_intrinsics(), 0.3, -0.1, 900.0);
  const CameraModel same = posed_camera(base, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  expect_same_camera(same, base, 1e-15);
}

TEST(PosedCamera, SeesEachPointWhereTheCameraSeesItMovedByThePose) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.4, axis).toRotationMatrix();
  const Eigen::Vector3d t(12, -7, 20);
  CameraModel distorted = perspective_intrinsics();
  distorted.distortion = {0.05, -0.01, 0.001, -0.002, 0.0};
  const CameraModel cameras[3] = {ideal_rig(640, 480, 2.0).front,
                                  camera_at(perspective_intrinsics(), 0.2, 0.1, 1000.0),
                                  camera_at(distorted, -1.2, 0.0, 800.0)};
  for (const CameraModel& c : cameras) {
    const CameraModel posed = posed_camera(c, r, t);
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d x = 100 * Eigen::Vector3d(u(rng), u(rng), u(rng));
      const Eigen::Vector2d want = project(c, r * x + t);
      EXPECT_LT((project(posed, x) - want).norm(), 1e-9 * (1 + want.norm())) << x.transpose();
      EXPECT_NEAR(depth(posed, x), depth(c, r * x + t), 1e-9);
    }
  }
}

TEST(PosedCamera, RefusesWhatIsNotARotationAndNonFiniteInput) {
  const CameraModel base = camera_at(perspective_intrinsics(), 0.0, 0.0, 1000.0);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d t(1, 2, 3);
  EXPECT_NO_THROW(posed_camera(base, r, t));
  EXPECT_THROW(posed_camera(base, 1.01 * r, t), std::invalid_argument);  // scaled
  const Eigen::Matrix3d reflection = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  EXPECT_THROW(posed_camera(base, reflection * r, t), std::invalid_argument);
  Eigen::Matrix3d nan = r;
  nan(1, 2) = NAN;
  EXPECT_THROW(posed_camera(base, nan, t), std::invalid_argument);
  EXPECT_THROW(posed_camera(base, r, Eigen::Vector3d(0, INFINITY, 0)), std::invalid_argument);
  CameraModel bad_pose = base;
  bad_pose.cam_from_head.translation().x() = NAN;
  EXPECT_THROW(posed_camera(bad_pose, r, t), std::invalid_argument);
}

TEST(CameraAt, StraightDownStaysAProperRotation) {
  const CameraModel c = camera_at(perspective_intrinsics(), 0.2, M_PI / 2, 800.0);
  const Eigen::Matrix3d r = c.cam_from_head.linear();
  EXPECT_NEAR((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-9);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
  EXPECT_TRUE(view_direction(c).isApprox(Eigen::Vector3d(0, -1, 0), 1e-9));
}

TEST(CameraAt, PerspectiveMatchesPinholeAndDistortion) {
  CameraModel c = camera_at(perspective_intrinsics(), 0.0, 0.0, 1000.0);
  // A point 50 mm right of the axis, 100 mm in front of the origin: z_cam = 900.
  const Eigen::Vector2d p = project(c, Eigen::Vector3d(50, 0, 100));
  EXPECT_NEAR(p.x(), 320.0 + 1600.0 * 50.0 / 900.0, 1e-9);
  c.distortion = {0.1, 0.0, 0.0, 0.0, 0.0};
  const double x = 50.0 / 900.0;
  EXPECT_NEAR(project(c, Eigen::Vector3d(50, 0, 100)).x(), 320.0 + 1600.0 * x * (1 + 0.1 * x * x),
              1e-9);
}

TEST(CameraAt, PointBehindPerspectiveCameraHasNoPixel) {
  const CameraModel c = camera_at(perspective_intrinsics(), 0.0, 0.0, 500.0);
  EXPECT_TRUE(project(c, Eigen::Vector3d(0, 0, 600)).hasNaN());
  EXPECT_TRUE(project(c, Eigen::Vector3d(0, 0, 500)).hasNaN());  // at the centre
  EXPECT_FALSE(project(c, Eigen::Vector3d(0, 0, 499)).hasNaN());
}

TEST(CameraAt, RejectsBadDistanceAndNonFiniteAngles) {
  EXPECT_THROW(camera_at(perspective_intrinsics(), 0, 0, 0.0), std::invalid_argument);
  EXPECT_THROW(camera_at(perspective_intrinsics(), 0, 0, -5.0), std::invalid_argument);
  EXPECT_THROW(camera_at(perspective_intrinsics(), NAN, 0, 100.0), std::invalid_argument);
  EXPECT_THROW(camera_at(perspective_intrinsics(), 0, INFINITY, 100.0), std::invalid_argument);
  // Orthographic cameras ignore the distance: zero is a valid degenerate value.
  CameraModel ortho;
  EXPECT_NO_THROW(camera_at(ortho, 0, 0, 0.0));
}

TEST(IdealRig, RejectsBadSizeAndScale) {
  EXPECT_THROW(ideal_rig(0, 480, 1.0), std::invalid_argument);
  EXPECT_THROW(ideal_rig(640, -1, 1.0), std::invalid_argument);
  EXPECT_THROW(ideal_rig(640, 480, 0.0), std::invalid_argument);
  EXPECT_THROW(ideal_rig(640, 480, NAN), std::invalid_argument);
  const RigCalibration tiny = ideal_rig(1, 1, 1.0);  // degenerate but valid
  EXPECT_NEAR(project(tiny.front, Eigen::Vector3d::Zero()).x(), 0.5, 1e-12);
}

TEST(RigFile, RoundTripsIdealAndPerspectiveRigs) {
  const fs::path dir = testing::temp_dir("rig_round_trip");
  const RigCalibration ideal = ideal_rig(640, 480, 1.6);
  write_rig(ideal, (dir / "ideal.yaml").string());
  const RigCalibration a = read_rig((dir / "ideal.yaml").string());
  expect_same_camera(a.front, ideal.front);
  expect_same_camera(a.side, ideal.side);
  EXPECT_EQ(a.source, "ideal");

  RigCalibration persp;
  persp.front = camera_at(perspective_intrinsics(), 0.01, -0.02, 1000.0);
  persp.side = camera_at(perspective_intrinsics(), M_PI / 2 + 0.03, 0.0, 950.0);
  persp.side.distortion = {-0.1, 0.02, 0.001, -0.002, 0.0005};
  persp.source = "sim";
  write_rig(persp, (dir / "persp.yaml").string());
  EXPECT_FALSE(fs::exists(dir / "persp.yaml.tmp.yaml"));
  const RigCalibration b = read_rig((dir / "persp.yaml").string());
  expect_same_camera(b.front, persp.front);
  expect_same_camera(b.side, persp.side);
  const Eigen::Vector3d p(12, -30, 80);
  EXPECT_LT((project(b.side, p) - project(persp.side, p)).norm(), 1e-9);
}

TEST(RigFile, WriteToMissingFolderThrows) {
  const fs::path dir = testing::temp_dir("rig_write_missing");
  EXPECT_THROW(write_rig(ideal_rig(64, 48, 1.0), (dir / "no" / "such" / "rig.yaml").string()),
               std::runtime_error);
}

TEST(RigFile, SharedBadInputsThrowNamingTheFile) {
  for (const char* name : {"rig_missing_fields.yaml", "rig_nan_focal.yaml", "rig_not_yaml.yaml"}) {
    const std::string path = bad_input(name);
    ASSERT_TRUE(fs::exists(path)) << path;
    try {
      read_rig(path);
      ADD_FAILURE() << name << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_rig("/nonexistent/rig.yaml"), std::runtime_error);
  EXPECT_THROW(read_rig(testing::temp_dir("rig_dir").string()), std::runtime_error);
}

// Each case: a valid file with one field broken; the error must name the field's problem.
TEST(RigFile, MalformedFieldsThrowNamingTheField) {
  const fs::path dir = testing::temp_dir("rig_malformed");
  const std::string good = valid_rig_text(dir);
  struct Case {
    std::string from, to, expect;
  };
  const Case cases[] = {
      {"projection: orthographic", "projection: fisheye", "projection"},
      {"width: 640", "width: 0", "image size"},
      {"width: 640", "width: abc", "image size"},
      {"height: 480", "height: 100000", "image size"},
      {"data: [ 2.", "data: [ .nan", "camera_matrix"},
      {"data: [ 2.", "data: [ -2.", "camera_matrix"},
      {"data: [ 2.", "data: [ 1e300", "camera_matrix"},  // finite but absurd focal
      {"data: [ 2.", "data: [ .inf", "camera_matrix"},
      {"front:", "frontal:", "missing camera section"},
      {"rows: 3", "rows: 1", "camera_matrix"},
      {"cam_from_head: !!opencv-matrix\n      rows: 4\n      cols: 4\n      dt: d\n      data: [ "
       "1.",
       "cam_from_head: !!opencv-matrix\n      rows: 4\n      cols: 4\n      dt: d\n      data: [ "
       "2.",
       "rotation"},
      {"orthoface_rig: 1", "orthoface_rigs: 1", "orthoface_rig"},
  };
  int i = 0;
  for (const Case& c : cases) {
    const auto at = good.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from << "\n" << good;
    std::string text = good;
    text.replace(at, c.from.size(), c.to);
    const fs::path p = dir / ("bad" + std::to_string(i++) + ".yaml");
    write_text(p, text);
    try {
      read_rig(p.string());
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
  }
}

// The view camera stands at the front camera's distance with its intrinsics.
TEST(ViewCamera, IsTheFrontCameraTurnedAtItsDistance) {
  RigCalibration rig;
  rig.front = camera_at(perspective_intrinsics(), 0.0, 0.0, 750.0);
  const CameraModel c = view_camera(rig, 30, -10);
  const CameraModel expected = camera_at(rig.front, 30 * M_PI / 180, -10 * M_PI / 180, 750.0);
  EXPECT_NEAR((c.cam_from_head.matrix() - expected.cam_from_head.matrix()).norm(), 0, 1e-9);
  EXPECT_EQ(c.fx, rig.front.fx);
  EXPECT_NEAR(c.cam_from_head.inverse().translation().norm(), 750.0, 1e-9);
  EXPECT_EQ(view_camera(rig, 0, 0).cam_from_head.matrix(), rig.front.cam_from_head.matrix());
}

TEST(ViewCamera, AFrontCameraAtTheOriginStandsOneMillimetreOff) {
  RigCalibration rig;  // identity pose: distance 0
  rig.front = perspective_intrinsics();
  EXPECT_NEAR(view_camera(rig, 45, 0).cam_from_head.inverse().translation().norm(), 1.0, 1e-12);
  EXPECT_THROW(view_camera(rig, NAN, 0), std::invalid_argument);
  EXPECT_THROW(view_camera(rig, 0, INFINITY), std::invalid_argument);
}

TEST(PhotographedSideSign, FollowsTheSideCamera) {
  const RigCalibration rig = ideal_rig(640, 480, 1.6);
  EXPECT_EQ(photographed_side_sign(rig), 1.0);                     // side camera at +x
  EXPECT_EQ(photographed_side_sign(photo_rig(rig, false)), -1.0);  // reflected to -x
  EXPECT_EQ(photographed_side_sign(photo_rig(rig, true)), 1.0);
}

// A side photo taken from the subject's right (-x): the model mirrors its observation into the
// +x convention, photo_rig() puts the camera back where it stood.
TEST(PhotoRig, ReflectsTheSideCameraToMinusX) {
  const RigCalibration rig = ideal_rig(640, 480, 2.0);
  EXPECT_EQ(photo_rig(rig, true).side.cam_from_head.matrix(), rig.side.cam_from_head.matrix());
  const RigCalibration right = photo_rig(rig, false);
  EXPECT_NEAR((view_direction(right.side) - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);
  const CameraModel at_minus_x = view_camera(rig, -90, 0);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(10, 20, 30), Eigen::Vector3d(-40, -5, 60)}) {
    const Eigen::Vector2d mirrored = project(rig.side, Eigen::Vector3d(-p.x(), p.y(), p.z()));
    const Eigen::Vector2d seen = project(right.side, p);
    EXPECT_NEAR(seen.x(), rig.side.width - mirrored.x(), 1e-9);  // columns mirrored
    EXPECT_NEAR(seen.y(), mirrored.y(), 1e-9);
    EXPECT_NEAR((seen - project(at_minus_x, p)).norm(), 0, 1e-9);
  }
}

TEST(PhotoRig, TangentialDistortionIsReflected) {
  RigCalibration rig;
  rig.side = camera_at(perspective_intrinsics(), M_PI / 2, 0.0, 1000.0);
  rig.side.distortion = {0.1, -0.05, 0.002, 0.003, 0.01};
  const RigCalibration right = photo_rig(rig, false);
  EXPECT_EQ(right.side.distortion, (std::vector<double>{0.1, -0.05, 0.002, -0.003, 0.01}));
  const Eigen::Vector3d p(10, 20, 30);
  const Eigen::Vector2d mirrored = project(rig.side, Eigen::Vector3d(-p.x(), p.y(), p.z()));
  EXPECT_NEAR(project(right.side, p).x(), rig.side.width - mirrored.x(), 1e-9);
}

// Any plane: the reflected camera's image of p is the camera's image of p's mirror image,
// flipped left to right.
TEST(Reflected, SeesTheMirrorImageFlipped) {
  const RigCalibration rig = ideal_rig(640, 480, 2.0);
  const Eigen::Vector3d n = Eigen::Vector3d(1, 0.1, 0.3).normalized();
  const Eigen::Vector4d plane(n.x(), n.y(), n.z(), 5.0);
  for (const CameraModel& c :
       {view_camera(rig, 30, 10), camera_at(perspective_intrinsics(), -0.4, 0.1, 900.0)}) {
    const CameraModel r = reflected(c, plane);
    EXPECT_NEAR(r.cam_from_head.linear().determinant(), 1.0, 1e-12);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(10, 20, 30), Eigen::Vector3d(-40, -5, 60)}) {
      const Eigen::Vector3d m = p - 2 * (n.dot(p) - plane.w()) * n;
      const Eigen::Vector2d seen = project(r, p), mirrored = project(c, m);
      EXPECT_NEAR(seen.x(), c.width - mirrored.x(), 1e-9);
      EXPECT_NEAR(seen.y(), mirrored.y(), 1e-9);
    }
  }
  EXPECT_THROW(reflected(rig.front, Eigen::Vector4d(0, 0, 0, 0)), std::invalid_argument);
  EXPECT_THROW(reflected(rig.front, Eigen::Vector4d(NAN, 0, 0, 0)), std::invalid_argument);
  CameraModel bad = rig.front;
  bad.fx = 0;
  EXPECT_THROW(reflected(bad, Eigen::Vector4d(1, 0, 0, 0)), std::invalid_argument);
}

TEST(CameraProblem, NamesWhatIsWrong) {
  const CameraModel good = ideal_rig(640, 480, 2.0).front;
  EXPECT_EQ(camera_problem(good), "");
  auto problem = [&](auto change) {
    CameraModel c = good;
    change(c);
    return camera_problem(c);
  };
  EXPECT_NE(problem([](CameraModel& c) { c.height = 0; }).find("image size"), std::string::npos);
  EXPECT_NE(problem([](CameraModel& c) { c.fx = INFINITY; }).find("fx"), std::string::npos);
  EXPECT_NE(problem([](CameraModel& c) { c.fy = 1e300; }).find("fx, fy"), std::string::npos);
  EXPECT_NE(problem([](CameraModel& c) { c.fx = -1; }).find("fx"), std::string::npos);
  EXPECT_NE(problem([](CameraModel& c) { c.cy = NAN; }).find("cx, cy"), std::string::npos);
  EXPECT_NE(problem([](CameraModel& c) { c.cam_from_head.translation().x() = NAN; }).find("pose"),
            std::string::npos);
}

TEST(PhotoRig, RefusesABadSideCamera) {
  RigCalibration bad = ideal_rig(640, 480, 2.0);
  bad.side.width = 0;
  EXPECT_THROW(photo_rig(bad, false), std::invalid_argument);
  bad = ideal_rig(640, 480, 2.0);
  bad.side.fx = NAN;
  EXPECT_THROW(photo_rig(bad, false), std::invalid_argument);
  EXPECT_NO_THROW(photo_rig(bad, true));  // unchanged: nothing to reflect
}

TEST(RigFile, EmptyFileThrows) {
  const fs::path dir = testing::temp_dir("rig_empty");
  write_text(dir / "empty.yaml", "");
  EXPECT_THROW(read_rig((dir / "empty.yaml").string()), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::capture
