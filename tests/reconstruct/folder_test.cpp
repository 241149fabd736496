// The reconstruction folder: written by write_reconstruction, read back by read_reconstruction,
// and a view textured from either in one call (view_synthesizer).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "model/symmetry.h"
#include "reconstruct/reconstruction.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::reconstruct {
namespace {

namespace fs = std::filesystem;

// One sim subject reconstructed with its rig, written once for every test of this file.
class Folder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const sim::Capture cap = sim::simulate_capture(sim::make_head(3), sim::RigOptions{});
    ReconstructOptions o;
    o.rig = cap.nominal_rig;
    rec_ = new Reconstruction(from_photos(cap.front, cap.side, o));
    dir_ = new fs::path(testing::temp_dir("reconstruct_folder") / "rec");
    write_reconstruction(*rec_, dir_->string());
  }
  static void TearDownTestSuite() {
    delete rec_;
    delete dir_;
  }
  static Reconstruction* rec_;
  static fs::path* dir_;
};
Reconstruction* Folder::rec_ = nullptr;
fs::path* Folder::dir_ = nullptr;

TEST_F(Folder, ReadsBackWhatWasWritten) {
  const Reconstruction back = read_reconstruction(dir_->string());
  ASSERT_EQ(back.mesh.vertices.size(), rec_->mesh.vertices.size());
  ASSERT_EQ(back.mesh.triangles, rec_->mesh.triangles);
  for (size_t i = 0; i < back.mesh.vertices.size(); ++i)
    ASSERT_LT((back.mesh.vertices[i] - rec_->mesh.vertices[i]).norm(), 1e-3) << i;
  EXPECT_EQ(cv::norm(back.front, rec_->front, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(back.side, rec_->side, cv::NORM_INF), 0);
  EXPECT_NEAR(back.rig.side.fx, rec_->rig.side.fx, 1e-6);
  EXPECT_LT(
      (back.photo_rig.side.cam_from_head.matrix() - rec_->photo_rig.side.cam_from_head.matrix())
          .norm(),
      1e-6);
  ASSERT_FALSE(rec_->side_mask.empty());
  EXPECT_EQ(cv::countNonZero(back.side_mask != rec_->side_mask), 0);
  ASSERT_EQ(back.landmarks.size(), rec_->landmarks.size());
  for (const auto& [name, p] : rec_->landmarks)
    EXPECT_LT((back.landmarks.at(name) - p).norm(), 1e-3) << name;
  EXPECT_EQ(back.observation.side_faces_left, rec_->observation.side_faces_left);
  ASSERT_FALSE(rec_->front_silhouette.empty());
  EXPECT_EQ(cv::countNonZero(back.front_silhouette != rec_->front_silhouette), 0);
  EXPECT_EQ(cv::countNonZero(back.side_silhouette != rec_->side_silhouette), 0);
  EXPECT_TRUE(back.front_plate.empty());  // reconstructed without a clean plate
  // The head's measured turn (mirror_plane turns the face's plane by it).
  ASSERT_TRUE(std::isfinite(rec_->report.head_yaw_deg));
  EXPECT_NEAR(back.report.head_yaw_deg, rec_->report.head_yaw_deg, 1e-9);
  EXPECT_EQ(back.report.head_turn_corrected, rec_->report.head_turn_corrected);
}

// A head modelled facing front though it was turned: its landmarks' plane (here of a frontal
// face) turns by the measured turn; a head turned back, or whose turn was not measured, keeps it.
TEST(MirrorPlane, TurnsWithAHeadModelledFacingFront) {
  Reconstruction r;
  r.landmarks = {{"eye_left_outer", {45, 0, 60}}, {"eye_right_outer", {-45, 0, 60}},
                 {"mouth_left", {25, -60, 70}},   {"mouth_right", {-25, -60, 70}},
                 {"nose_tip", {0, -30, 100}},     {"chin", {0, -110, 80}}};
  const auto yaw_of = [](const std::optional<Eigen::Vector4d>& plane) {
    return std::atan2(plane->z(), plane->x()) * 180 / M_PI;
  };
  ASSERT_TRUE(mirror_plane(r));
  EXPECT_NEAR(yaw_of(mirror_plane(r)), 0, 1e-9);  // not measured
  r.report.head_yaw_deg = -25;
  r.report.head_turn_corrected = true;
  EXPECT_NEAR(yaw_of(mirror_plane(r)), 0, 1e-9);  // turned back: the landmarks hold the turn
  r.report.head_turn_corrected = false;
  const auto plane = mirror_plane(r);
  EXPECT_NEAR(yaw_of(plane), 25, 1e-9);
  EXPECT_NEAR(plane->head<3>().norm(), 1, 1e-12);
  // Through the landmarks' centre, as the unturned plane is.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& [name, p] : r.landmarks) centre += p;
  centre /= double(r.landmarks.size());
  EXPECT_NEAR(plane->head<3>().dot(centre), plane->w(), 1e-9);
  // Landmarks whose own plane lies at a small angle: it is replaced by the turn, not added to.
  r.landmarks.at("eye_left_outer").z() += 8;
  r.landmarks.at("mouth_left").z() += 4;
  ASSERT_GT(std::abs(yaw_of(model::mid_sagittal_plane(r.landmarks))), 2);
  EXPECT_NEAR(yaw_of(mirror_plane(r)), 25, 1e-9);
  r.landmarks = {{"nose_tip", {0, -30, 100}}};
  EXPECT_FALSE(mirror_plane(r));  // no left / right pairs
}

// The neck twists into the body: the face and everything above the chin turn fully, the neck's
// lowest vertices not at all, and the weights never leave 0..1; the face mesh alone has none.
TEST_F(Folder, TheNeckTurnsLessTheLowerItIs) {
  const ViewModel whole = view_model(*rec_, HeadExtent::Whole);
  ASSERT_EQ(whole.turn_weights.size(), whole.mesh.vertices.size());
  double chin = 1e9, bottom = 1e9;
  for (const Eigen::Vector3d& p : rec_->mesh.vertices) chin = std::min(chin, p.y());
  size_t lowest = 0;
  for (size_t i = 0; i < whole.mesh.vertices.size(); ++i) {
    const double y = whole.mesh.vertices[i].y();
    if (y < bottom) bottom = y, lowest = i;
    EXPECT_GE(whole.turn_weights[i], 0.0f);
    EXPECT_LE(whole.turn_weights[i], 1.0f);
    if (i < size_t(whole.face_vertices) || y >= chin) {
      EXPECT_EQ(whole.turn_weights[i], 1.0f);
    }
  }
  ASSERT_GT(chin - bottom, 20);  // the sim head's hull has a neck
  EXPECT_EQ(whole.turn_weights[lowest], 0.0f);
  EXPECT_TRUE(view_model(*rec_, HeadExtent::Face).turn_weights.empty());
}

// The whole head turned 30 degrees covers the true head's silhouette; the face mesh alone does
// not (the truth is the sim head itself, turned about the same pivot).
TEST_F(Folder, TheWholeHeadCoversTheTrueHeadsSilhouette) {
  const ViewModel whole = view_model(*rec_, HeadExtent::Whole);
  const ViewModel face = view_model(*rec_, HeadExtent::Face);
  ASSERT_GT(whole.mesh.vertices.size(), face.mesh.vertices.size());
  EXPECT_EQ(whole.face_vertices, int(rec_->mesh.vertices.size()));
  EXPECT_LT(whole.pivot.z(), rec_->landmarks.at("chin").z() - 30);  // the neck, behind the chin
  const sim::Head head = sim::make_head(3);
  auto iou = [&](const ViewModel& m) {
    const capture::CameraModel camera = m.camera(rec_->rig.front, 30, 0);
    render::SynthesisOptions o;
    o.float_textures = false;
    const cv::Mat view = view_synthesizer(*rec_, m)->render(camera, o).view.mask;
    cv::Mat truth = render::render_once(head.mesh, camera).mask;
    // The sim head has no neck below the frame's reach of the hull: compare above the pivot's
    // row minus the neck's 40 mm.
    const int bottom = int(capture::project(camera, whole.pivot - Eigen::Vector3d(0, 40, 0)).y());
    const cv::Rect above(0, 0, truth.cols, std::clamp(bottom, 1, truth.rows));
    return double(cv::countNonZero(view(above) & truth(above))) /
           cv::countNonZero(view(above) | truth(above));
  };
  const double w = iou(whole), f = iou(face);
  std::printf("sim subject 3, 30 deg: head-silhouette IoU whole %.3f, face mesh %.3f\n", w, f);
  EXPECT_GT(w, 0.9);
  EXPECT_GT(w, f + 0.1);
}

// A view whose neck twists into the body fades into the photo's own neck only where its neck
// has turned nearly back: a neck still turned with the head, blended with the photo's, doubles
// the collar.
TEST_F(Folder, TheNeckFadesIntoThePhotoWhereItHasTurnedBack) {
  const ViewModel model = view_model(*rec_, HeadExtent::Whole);
  ASSERT_EQ(model.turn_weights.size(), model.mesh.vertices.size());
  const auto synth = view_synthesizer(*rec_, model);
  const ViewScene scene = view_scene(*rec_, *synth, true);
  ASSERT_TRUE(std::isfinite(scene.fade_from_row));
  // A neck that turns whole with the head (no twist) fades out higher up, as before.
  EXPECT_LT(view_scene(*rec_, *synth).fade_from_row, scene.fade_from_row - 5);
  int below = 0;
  float most = 0;
  for (size_t i = 0; i < model.mesh.vertices.size(); ++i) {
    if (capture::project(rec_->photo_rig.front, model.mesh.vertices[i]).y() < scene.fade_from_row)
      continue;
    ++below;
    most = std::max(most, model.turn_weights[i]);
  }
  EXPECT_GT(below, 0);
  // (1 when the fade began a third of the way down from the chin)
  EXPECT_LE(most, 0.6f) << "the view fades out where its neck still turns with the head";
}

// The scene of a composited view: the head gone from the front photo, and at yaw 0 the
// composite gives the front photo back.
TEST_F(Folder, TheSceneLosesTheHeadAndYawZeroGivesThePhotoBack) {
  const ViewModel model = view_model(*rec_, HeadExtent::Whole);
  const auto synth = view_synthesizer(*rec_, model);
  const ViewScene scene = view_scene(*rec_, *synth);
  const cv::Mat head = rec_->front_silhouette;
  cv::Mat diff;
  cv::absdiff(scene.background, rec_->front, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::mean(diff, head)[0], 20);  // the head is gone
  ASSERT_TRUE(std::isfinite(scene.fade_from_row));
  const render::RenderResult zero = synth->render(rec_->photo_rig.front).view;
  const cv::Mat at_zero = scene.composite(zero);
  cv::Mat inside;  // the view's own pixels, its feathered edge left out
  cv::erode(zero.mask, inside, cv::Mat::ones(5, 5, CV_8U));
  const double head_db = render::psnr(rec_->front, at_zero, inside),
               frame_db = render::psnr(rec_->front, at_zero, cv::Mat());
  std::printf("yaw 0 composite vs the front photo: %.1f dB on the head, %.1f dB the frame\n",
              head_db, frame_db);
  EXPECT_GT(head_db, 40.0);
  EXPECT_GT(frame_db, 28.0);  // the ring around the head is the scene's fill
  // Over a live frame: the body is the frame's, the head's place the scene's.
  cv::Mat frame = rec_->front.clone();
  frame.setTo(cv::Scalar(10, 200, 30), ~scene.removed);
  const cv::Mat live = scene.composite(zero, frame);
  cv::Point outside(0, 0);
  EXPECT_EQ(live.at<cv::Vec3b>(outside), cv::Vec3b(10, 200, 30));
  cv::Mat in_removed_only = scene.removed & ~zero.mask;
  std::vector<cv::Point> filled;
  cv::findNonZero(in_removed_only, filled);
  ASSERT_FALSE(filled.empty());
  EXPECT_EQ(live.at<cv::Vec3b>(filled.front()), scene.background.at<cv::Vec3b>(filled.front()));
  // Within keep_px outside the view's head the frame stays (the real head's edge and scene),
  // further out the removed region is the scene's fill.
  constexpr int kKeep = 6;
  const cv::Mat removed_before = scene.removed.clone();
  const cv::Mat kept = scene.composite(zero, frame, kKeep);
  EXPECT_EQ(cv::countNonZero(scene.removed != removed_before), 0);  // the scene is left as it was
  cv::Mat near_head, band, beyond;
  cv::dilate(zero.mask, near_head,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * kKeep + 1, 2 * kKeep + 1}));
  band = scene.removed & near_head & ~zero.mask;
  beyond = scene.removed & ~near_head;
  std::vector<cv::Point> in_band, out_band;
  cv::findNonZero(band, in_band);
  cv::findNonZero(beyond, out_band);
  ASSERT_FALSE(in_band.empty());
  ASSERT_FALSE(out_band.empty());
  for (const cv::Point& p : {in_band.front(), in_band.back()})
    EXPECT_EQ(kept.at<cv::Vec3b>(p), frame.at<cv::Vec3b>(p)) << p;
  for (const cv::Point& p : {out_band.front(), out_band.back()})
    EXPECT_EQ(kept.at<cv::Vec3b>(p), scene.background.at<cv::Vec3b>(p)) << p;
  EXPECT_THROW(scene.composite(zero, cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(scene.composite(zero, frame, -1), std::invalid_argument);
  const ViewScene half = scene.fitted(scene.background.cols / 2, scene.background.rows / 2);
  EXPECT_NEAR(half.fade_from_row, scene.fade_from_row / 2, 1);
}

// The fixture's reconstruction with `block` of its front photo painted `colour` and added to its
// silhouette (new buffers: assigning an expression to the copy's Mat would write into the
// fixture's), and the scene of its whole-head view; `head` is that view's mask from the front
// camera, given to `make_block` to draw round.
struct PaintedScene {
  ViewScene scene;
  cv::Mat block;
  cv::Vec3b background;
};
PaintedScene painted_scene(
    const Reconstruction& fixture, cv::Vec3b colour,
    const std::function<cv::Mat(const Reconstruction&, const cv::Mat&)>& make_block) {
  Reconstruction r = fixture;
  const ViewModel model = view_model(r, HeadExtent::Whole);
  const auto synth = view_synthesizer(r, model);
  const cv::Mat head = synth->render(r.photo_rig.front).view.mask > 0;
  PaintedScene p;
  p.block = make_block(r, head) & ~head;
  r.front = r.front.clone();
  r.front.setTo(colour, p.block);
  cv::Mat subject;
  cv::bitwise_or(r.front_silhouette, p.block, subject);
  r.front_silhouette = subject;
  p.background = r.front.at<cv::Vec3b>(2, 2);
  p.scene = view_scene(r, *synth);
  return p;
}

// Whether the mean colour over `mask` lies nearer `a` than `b` (sum of the channels' distances).
bool mean_nearer(const cv::Mat& image, const cv::Mat& mask, cv::Vec3b a, cv::Vec3b b) {
  const cv::Scalar mean = cv::mean(image, mask);
  double to_a = 0, to_b = 0;
  for (int c = 0; c < 3; ++c) to_a += std::abs(mean[c] - a[c]), to_b += std::abs(mean[c] - b[c]);
  return to_a < to_b;
}

double front_row(const Reconstruction& r, const char* landmark) {
  return capture::project(r.photo_rig.front, r.landmarks.at(landmark)).y();
}

// A collar standing beside the jaw (the subject below the mouth, outside the head) is removed
// with the head's hair band and filled from the collar around it, not from the background: from
// the background it showed as dark bays beside the turned neck.
TEST_F(Folder, TheSceneFillsACollarBesideTheJawFromTheCollar) {
  const int mouth = int(std::ceil(front_row(*rec_, "mouth_left"))) + 2;
  const int chin = int(front_row(*rec_, "chin_bottom"));
  ASSERT_LT(mouth + 4, chin);
  const cv::Vec3b collar(250, 250, 250);
  const PaintedScene p = painted_scene(*rec_, collar, [&](const Reconstruction& r, const cv::Mat&) {
    cv::Mat block = cv::Mat::zeros(r.front.size(), CV_8U);
    block.rowRange(mouth, r.front.rows).setTo(255);
    return block;
  });
  const cv::Mat filled = p.scene.removed & p.block;
  filled.rowRange(chin, filled.rows).setTo(0);
  ASSERT_GT(cv::countNonZero(filled), 50);
  EXPECT_TRUE(mean_nearer(p.scene.background, filled, collar, p.background));
}

// Long hair round the face: the band of it removed beside the head is filled from the hair
// around it, not from the background (dark curtain in the hair beside a turned face).
TEST_F(Folder, TheSceneFillsHairBesideTheFaceFromTheHair) {
  const int mouth = int(front_row(*rec_, "mouth_left")) - 2;
  const cv::Vec3b hair(30, 60, 120);
  const PaintedScene p =
      painted_scene(*rec_, hair, [&](const Reconstruction& r, const cv::Mat& head) {
        cv::Mat near_head;  // hair a third of the photo wide round the head, down to the mouth
        cv::dilate(head, near_head, cv::Mat::ones(1, r.front.cols / 3, CV_8U));
        near_head.rowRange(mouth, near_head.rows).setTo(0);
        return near_head;
      });
  const cv::Mat filled = p.scene.removed & p.block;
  ASSERT_GT(cv::countNonZero(filled), 50);
  EXPECT_TRUE(mean_nearer(p.scene.background, filled, hair, p.background));
}

// The folder on disk and the reconstruction in memory give the same view.
TEST_F(Folder, AViewFromTheFolderEqualsTheViewFromMemory) {
  const Reconstruction back = read_reconstruction(dir_->string());
  const capture::CameraModel camera = capture::view_camera(rec_->rig, 30, 0);
  render::SynthesisOptions o;
  o.float_textures = false;
  const cv::Mat a = view_synthesizer(*rec_)->render(camera, o).view.image;
  const cv::Mat b = view_synthesizer(back)->render(camera, o).view.image;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(render::psnr(a, b, cv::Mat()), 50.0);
  EXPECT_GT(cv::countNonZero(a.reshape(1)), a.total() / 20);  // a head was drawn
}

TEST_F(Folder, OptionalFilesMayBeAbsent) {
  const fs::path bare = testing::temp_dir("reconstruct_bare");
  for (const char* f : {"head.obj", "front.png", "side.png"}) fs::copy_file(*dir_ / f, bare / f);
  const Reconstruction r = read_reconstruction(bare.string());
  EXPECT_TRUE(r.landmarks.empty());
  EXPECT_TRUE(r.side_mask.empty());
  EXPECT_EQ(r.rig.front.width, r.front.cols);  // the ideal rig for the photo's size
  fs::remove_all(bare);
}

TEST_F(Folder, LandmarksAreReadOnlyWhenAskedFor) {
  EXPECT_TRUE(read_reconstruction(dir_->string(), {.landmarks = false}).landmarks.empty());
  EXPECT_FALSE(read_reconstruction(dir_->string()).landmarks.empty());
}

TEST_F(Folder, BadFoldersNameTheFolderAndTheFile) {
  const fs::path bad = testing::temp_dir("reconstruct_bad");
  auto expect_error = [&](const std::string& needle) {
    try {
      read_reconstruction(bad.string());
      ADD_FAILURE() << "no error, expected one naming " << needle;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
  };
  expect_error("head.obj");  // empty folder
  for (const char* f : {"head.obj", "front.png", "side.png", "landmarks.json", "rig.yaml"})
    fs::copy_file(*dir_ / f, bad / f);
  std::ofstream(bad / "front.png") << "not a png";
  expect_error("front.png");
  fs::copy_file(*dir_ / "front.png", bad / "front.png", fs::copy_options::overwrite_existing);
  {  // a truncated photo is refused (once decoded half-grey with libpng chatter on stderr)
    const std::string png = testing::slurp(*dir_ / "side.png");
    std::ofstream(bad / "side.png", std::ios::binary) << png.substr(0, png.size() / 2);
    expect_error("side.png");
    fs::copy_file(*dir_ / "side.png", bad / "side.png", fs::copy_options::overwrite_existing);
  }
  std::ofstream(bad / "landmarks.json") << "{\"landmarks\": [";
  expect_error("landmarks.json");
  std::ofstream(bad / "landmarks.json") << "{}";
  expect_error("landmarks.json");
  fs::remove(bad / "landmarks.json");
  std::ofstream(bad / "report.json") << "{\"head_yaw_deg\": ";
  expect_error("report.json");
  std::ofstream(bad / "report.json") << "{\"head_yaw_deg\": \"left\", \"head_turn_corrected\": 1}";
  expect_error("report.json");
  fs::remove(bad / "report.json");
  std::ofstream(bad / "rig.yaml") << "%YAML:1.0\nnothing: 1\n";
  expect_error("rig.yaml");
  fs::remove(bad / "rig.yaml");
  cv::imwrite((bad / "silhouette_front.png").string(), cv::Mat(10, 10, CV_8U, cv::Scalar(255)));
  cv::imwrite((bad / "silhouette_side.png").string(), cv::Mat(10, 10, CV_8U, cv::Scalar(255)));
  expect_error("silhouette_front.png");
  fs::remove(bad / "silhouette_front.png");
  fs::remove(bad / "silhouette_side.png");
  cv::imwrite((bad / "background_front.png").string(), cv::Mat(10, 10, CV_8UC3));
  expect_error("background_front.png");
  fs::remove_all(bad);
  EXPECT_THROW(read_reconstruction((bad / "missing").string()), std::runtime_error);
}

TEST(ViewSynthesizer, NeedsBothPhotos) {
  Reconstruction r;
  EXPECT_THROW(view_synthesizer(r), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::reconstruct
