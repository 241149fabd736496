// The reconstruction folder: written by write_reconstruction, read back by read_reconstruction,
// and a view textured from either in one call (view_synthesizer).
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "reconstruct/reconstruction.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "sim/head.h"
#include "sim/rig.h"
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
  std::ofstream(bad / "landmarks.json") << "{\"landmarks\": [";
  expect_error("landmarks.json");
  std::ofstream(bad / "landmarks.json") << "{}";
  expect_error("landmarks.json");
  fs::remove(bad / "landmarks.json");
  std::ofstream(bad / "rig.yaml") << "%YAML:1.0\nnothing: 1\n";
  expect_error("rig.yaml");
  fs::remove_all(bad);
  EXPECT_THROW(read_reconstruction((bad / "missing").string()), std::runtime_error);
}

TEST(ViewSynthesizer, NeedsBothPhotos) {
  Reconstruction r;
  EXPECT_THROW(view_synthesizer(r), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::reconstruct
