// `orthoface reconstruct` and `orthoface eval`, run as separate processes like scripts do.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "mesh/mesh_io.h"
#include "sim/truth_json.h"
#include "tests/common/run_command.h"
#include "tests/common/scene_photo.h"
#include "tests/common/test_data.h"
#include "vision/pts_io.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

using Result = testing::CommandResult;
using testing::slurp;

Result run(const std::string& args, const fs::path& work) {
  return testing::run_orthoface(args, work);
}

// One simulated subject shared by the tests of this file.
class Reconstruct : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    work_ = new fs::path(orthoface::testing::temp_dir("reconstruct_cli"));
    const Result r = run("simulate --subject 2 --out sim", *work_);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  static void TearDownTestSuite() { delete work_; }
  // Expects a failure with exactly one "error:" line and no output folder.
  static void expect_clean_error(const std::string& args, const std::string& needle) {
    const Result r = run(args, *work_);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "wanted '" << needle << "' in " << r.err;
    EXPECT_FALSE(fs::exists(*work_ / "bad_out")) << args;
    EXPECT_FALSE(fs::exists(*work_ / "bad_out.tmp")) << args;
  }
  static fs::path* work_;
};
fs::path* Reconstruct::work_ = nullptr;

TEST_F(Reconstruct, WithRigWritesFolderAndEvalMeasuresIt) {
  const Result r =
      run("reconstruct --front sim/front.png --side sim/side.png --rig sim/rig.yaml "
          "--out rec --k 6",
          *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"head.obj", "head.mtl", "head.png", "front.png", "side.png", "rig.yaml",
                        "landmarks.json", "observation.json", "report.json"})
    EXPECT_TRUE(fs::exists(*work_ / "rec" / f)) << f;
  EXPECT_FALSE(fs::exists(*work_ / "rec.tmp"));
  const auto report = nlohmann::json::parse(slurp(*work_ / "rec" / "report.json"));
  for (const char* stage : {"observe", "stereo", "adapt", "texture"})
    EXPECT_TRUE(report["stage_ms"].contains(stage)) << stage;
  EXPECT_NE(report["scale"].get<std::string>().find("rig file"), std::string::npos);
  EXPECT_GE(report["features_found"].size(), 10u);
  const Result e = run("eval rec --truth sim", *work_);
  ASSERT_EQ(e.code, 0) << e.err;
  const auto ev = nlohmann::json::parse(slurp(*work_ / "rec" / "eval.json"));
  EXPECT_LT(ev["relative_error"].get<double>(), 0.01);  // < 1 % of the face diagonal
  EXPECT_LT(ev["landmark_mean_mm"].get<double>(), 10.0);
  EXPECT_TRUE(fs::exists(*work_ / "rec" / "error.ply"));
  EXPECT_FALSE(cv::imread((*work_ / "rec" / "error.png").string()).empty());
  // One textured model: the folder's head.obj is what `render --export` writes (it was the mesh
  // textured from the front photo alone).
  const Result x = run("render rec --export exported.obj", *work_);
  ASSERT_EQ(x.code, 0) << x.err;
  const mesh::TriMesh head = mesh::read_mesh((*work_ / "rec" / "head.obj").string());
  const mesh::TriMesh exported = mesh::read_mesh((*work_ / "exported.obj").string());
  ASSERT_EQ(head.vertices.size(), exported.vertices.size());
  EXPECT_EQ(head.triangles, exported.triangles);
  double uv_gap = 0;
  for (size_t i = 0; i < head.uvs.size(); ++i)
    uv_gap = std::max(uv_gap, (head.uvs[i] - exported.uvs[i]).norm());
  EXPECT_LT(uv_gap, 1e-6);
  ASSERT_EQ(head.texture.size(), exported.texture.size());
  EXPECT_EQ(cv::norm(head.texture, exported.texture, cv::NORM_INF), 0);
  EXPECT_NE(report["mesh"]["texture"].get<std::string>().find("both photos"), std::string::npos);
}

TEST_F(Reconstruct, WithoutRigTheReportSaysTheScaleIsAssumed) {
  const Result r =
      run("reconstruct --front sim/front.png --side sim/side.png --out norig "
          "--method interpolate",
          *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto report = nlohmann::json::parse(slurp(*work_ / "norig" / "report.json"));
  EXPECT_NE(report["scale"].get<std::string>().find("no rig file"), std::string::npos);
  EXPECT_EQ(report["rig_source"], "default (no rig file)");
  EXPECT_EQ(report["front_landmarker"], "consensus");
  EXPECT_TRUE(report["photographed_side_yaw_sign"] == 1.0 ||
              report["photographed_side_yaw_sign"] == -1.0);
}

// --head-turn and --turn-toward-side reach the model: any turn at all, either way, is turned
// back (the sim head reads a degree or so), and -1 never.
TEST_F(Reconstruct, HeadTurnFlagsReachTheModel) {
  for (const auto& [flags, corrected] :
       {std::pair{"--head-turn 0 --turn-toward-side", true}, std::pair{"--head-turn -1", false}}) {
    const Result r = run(std::string("reconstruct --front sim/front.png --side sim/side.png "
                                     "--rig sim/rig.yaml --out turn ") +
                             flags,
                         *work_);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto report = nlohmann::json::parse(slurp(*work_ / "turn" / "report.json"));
    EXPECT_EQ(report["head_turn_corrected"], corrected) << flags;
    EXPECT_TRUE(report["head_yaw_deg"].is_number()) << flags;
  }
}

TEST_F(Reconstruct, BadArgumentsGiveOneErrorLineAndNoOutput) {
  const std::string ok = "--front sim/front.png --side sim/side.png --out bad_out";
  expect_clean_error("reconstruct --side sim/side.png --out bad_out", "--front");
  expect_clean_error("reconstruct --front missing.png --side sim/side.png --out bad_out",
                     "missing.png");
  expect_clean_error("reconstruct " + ok + " --k 0", "--k");
  expect_clean_error("reconstruct " + ok + " --rig sim/rig.yaml --k 100000", "landmark count");
  expect_clean_error("reconstruct " + ok + " --method best", "--method");
  expect_clean_error("reconstruct " + ok + " --head-turn 91", "--head-turn");
  expect_clean_error("reconstruct " + ok + " --head-turn left", "--head-turn");
  expect_clean_error("reconstruct " + ok + " --side-camera up", "--side-camera");
  expect_clean_error("reconstruct " + ok + " --landmarker dlib", "--landmarker");
  std::ofstream(*work_ / "not_image.png") << "this is text";
  expect_clean_error("reconstruct --front not_image.png --side sim/side.png --out bad_out",
                     "not_image.png");
  std::ofstream(*work_ / "bad_rig.yaml") << "%YAML:1.0\n---\northoface_rig: 1\nfront: [1, 2\n";
  expect_clean_error("reconstruct " + ok + " --rig bad_rig.yaml", "bad_rig.yaml");
  // A rig for another image size: refused before anything is written (it was accepted, and the
  // model then refused by `render`).
  ASSERT_EQ(run("simulate --subject 2 --size 800x600 --out sim800", *work_).code, 0);
  expect_clean_error("reconstruct " + ok + " --rig sim800/rig.yaml", "800x600");
  // Photos without a face: nothing to reconstruct.
  cv::imwrite((*work_ / "blank.png").string(),
              cv::Mat(480, 640, CV_8UC3, cv::Scalar(200, 200, 200)));
  expect_clean_error("reconstruct --front blank.png --side blank.png --out bad_out", "");
}

// iBUG .pts landmarks of the true front pixels replace detection: the model is no worse, the
// observation says "user", and `detect --pts` writes the detected ones in the same form.
TEST_F(Reconstruct, FrontLandmarksFromAPtsFileReplaceDetection) {
  const sim::Truth truth = sim::read_truth_json((*work_ / "sim" / "landmarks.json").string());
  vision::Ibug68 pts;
  for (const auto& [name, k] : vision::kIbug68Landmarks) {
    const auto it = truth.landmarks.find(std::string(name));
    if (it != truth.landmarks.end() && it->second.visible_front)
      pts[k] = cv::Point2d(it->second.front_px.x(), it->second.front_px.y());
  }
  vision::write_pts(pts, (*work_ / "truth.pts").string());
  const std::string pair =
      "reconstruct --front sim/front.png --side sim/side.png --rig sim/rig.yaml ";
  ASSERT_EQ(run(pair + "--out rec_detected", *work_).code, 0);
  const Result r = run(pair + "--front-landmarks truth.pts --out rec_user", *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("front landmarks: "), std::string::npos) << r.out;
  double mean_mm[2], relative[2];
  for (int i = 0; i < 2; ++i) {
    const std::string dir = i == 0 ? "rec_detected" : "rec_user";
    ASSERT_EQ(run("eval " + dir + " --truth sim", *work_).code, 0);
    const auto ev = nlohmann::json::parse(slurp(*work_ / dir / "eval.json"));
    mean_mm[i] = ev["landmark_mean_mm"].get<double>();
    relative[i] = ev["relative_error"].get<double>();
  }
  EXPECT_LE(mean_mm[1], mean_mm[0] + 0.05) << "user " << mean_mm[1] << " detected " << mean_mm[0];
  EXPECT_LE(relative[1], relative[0] * 1.02 + 1e-4);
  const auto obs = nlohmann::json::parse(slurp(*work_ / "rec_user" / "observation.json"));
  EXPECT_EQ(obs["front"]["features"]["nose_tip"]["method"], "user");
  EXPECT_EQ(obs["front"]["features"]["eye_left_outer"]["x"].get<double>(), pts[45]->x);

  const Result d =
      run("detect --front sim/front.png --side sim/side.png --out det --pts det/f.pts", *work_);
  ASSERT_EQ(d.code, 0) << d.err;
  const vision::Ibug68 found = vision::read_pts((*work_ / "det" / "f.pts").string());
  int known = 0;
  for (const auto& p : found) known += p.has_value();
  EXPECT_GE(known, 14);
  expect_clean_error(
      "detect --front sim/front.png --side sim/side.png --out bad_out --pts "
      "nowhere/f.pts",
      "nowhere");
}

TEST_F(Reconstruct, BadFrontLandmarksGiveOneErrorLine) {
  const std::string ok = "reconstruct --front sim/front.png --side sim/side.png --out bad_out ";
  expect_clean_error(ok + "--front-landmarks missing.pts", "missing.pts");
  std::ofstream(*work_ / "short.pts") << "version: 1\nn_points: 68\n{\n1 2\n}\n";
  expect_clean_error(ok + "--front-landmarks short.pts", "short.pts");
  vision::Ibug68 far;
  far[30] = cv::Point2d(10, 900);  // below the 640x480 photo
  vision::write_pts(far, (*work_ / "far.pts").string());
  expect_clean_error(ok + "--front-landmarks far.pts", "far.pts");
}

// An OpenCV stereo calibration file of the sim's perspective rig works as --rig.
TEST_F(Reconstruct, AnOpenCvStereoFileIsARig) {
  ASSERT_EQ(run("simulate --subject 2 --rig perspective --out simp", *work_).code, 0);
  const capture::RigCalibration rig = capture::read_rig((*work_ / "simp" / "rig.yaml").string());
  capture::write_rig(rig, (*work_ / "stereo.yml").string(), capture::RigFormat::OpenCvStereo);
  const Result r =
      run("reconstruct --front simp/front.png --side simp/side.png --rig stereo.yml --out rec_cv",
          *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(run("eval rec_cv --truth simp", *work_).code, 0);
  const auto ev = nlohmann::json::parse(slurp(*work_ / "rec_cv" / "eval.json"));
  EXPECT_LT(ev["relative_error"].get<double>(), 0.01);
  expect_clean_error("calibrate --front-images a --side-images b --out r.yaml --rig-format colmap",
                     "--rig-format");
}

// A wrong pair (the photos swapped) is refused by the input check with exit 3 and one line
// naming the check; --force models it and report.json records the failed check.
TEST_F(Reconstruct, TheInputCheckRefusesSwappedPhotosUnlessForced) {
  const std::string swapped = "reconstruct --front sim/side.png --side sim/front.png --out bad_out";
  expect_clean_error(swapped, "error: input check swapped: ");
  EXPECT_EQ(run(swapped, *work_).code, 3);
  const Result forced =
      run("reconstruct --front sim/side.png --side sim/front.png --out forced --force", *work_);
  ASSERT_EQ(forced.code, 0) << forced.err;
  const auto report = nlohmann::json::parse(slurp(*work_ / "forced" / "report.json"));
  EXPECT_FALSE(report["input_check"]["swapped"]["passed"].get<bool>());
  EXPECT_EQ(report["warnings"][0].get<std::string>().rfind("input check swapped failed", 0), 0u)
      << report["warnings"];
  // A right pair: every check passed and is in the report.
  const Result right =
      run("reconstruct --front sim/front.png --side sim/side.png --out right", *work_);
  ASSERT_EQ(right.code, 0) << right.err;
  const auto ok = nlohmann::json::parse(slurp(*work_ / "right" / "report.json"));
  ASSERT_EQ(ok["input_check"].size(), 11u);
  for (const auto& [name, c] : ok["input_check"].items())
    EXPECT_TRUE(c["passed"].get<bool>()) << name;
  EXPECT_TRUE(ok["stage_ms"].contains("input_check"));
}

// In front of a cluttered scene the cameras' empty scenes (clean plates) cut the head out by
// difference: the model is as good as over a plain background (sim subject 6: 0.22 % plain,
// 0.23 % with plates; without, the drawn clutter's lines across the head cost 6.2 %).
TEST_F(Reconstruct, CleanPlatesHoldInFrontOfClutter) {
  ASSERT_EQ(run("simulate --subject 6 --background cluttered --out clutter", *work_).code, 0);
  const std::string pair =
      "reconstruct --front clutter/front.png --side clutter/side.png "
      "--rig clutter/rig.yaml ";
  const Result r = run(pair +
                           "--front-background clutter/background.png --side-background "
                           "clutter/background_side.png --out plates",
                       *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(run("eval plates --truth clutter", *work_).code, 0);
  const auto ev = nlohmann::json::parse(slurp(*work_ / "plates" / "eval.json"));
  EXPECT_LT(ev["relative_error"].get<double>(), 0.005);
  expect_clean_error(pair + "--front-background missing.png --out bad_out", "missing.png");
  cv::imwrite((*work_ / "small_plate.png").string(),
              cv::Mat(120, 160, CV_8UC3, cv::Scalar::all(0)));
  expect_clean_error(pair + "--side-background small_plate.png --out bad_out", "side background");
}

// Without plates, a head in front of a room is cut out around its face (vision/scene_cut.h), and
// report.json says so.
TEST_F(Reconstruct, ABusySceneWithoutPlatesIsCutOutAroundTheFace) {
  testing::write_scene_photo((*work_ / "room.png").string(), 1);
  ASSERT_EQ(run("simulate --subject 1 --background photo:room.png --out room", *work_).code, 0);
  const Result r =
      run("reconstruct --front room/front.png --side room/side.png --rig room/rig.yaml --out cut",
          *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(run("eval cut --truth room", *work_).code, 0);
  const auto ev = nlohmann::json::parse(slurp(*work_ / "cut" / "eval.json"));
  EXPECT_LT(ev["relative_error"].get<double>(), 0.01);
  EXPECT_NE(slurp(*work_ / "cut" / "report.json").find("front view: busy background"),
            std::string::npos);
}

// A side photo of twice the front's resolution (refused before: beyond 1.5x) is rescaled, and
// report.json says by how much.
TEST_F(Reconstruct, ASidePhotoOfAnotherSizeIsRescaled) {
  cv::Mat side = cv::imread((*work_ / "sim" / "side.png").string()), big;
  cv::resize(side, big, cv::Size(), 2.0, 2.0, cv::INTER_LINEAR);
  cv::imwrite((*work_ / "big_side.png").string(), big);
  const Result r =
      run("reconstruct --front sim/front.png --side big_side.png --out rescaled", *work_);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto report = nlohmann::json::parse(slurp(*work_ / "rescaled" / "report.json"));
  EXPECT_DOUBLE_EQ(report["side_photo_scale"].get<double>(), 0.5);
  EXPECT_EQ(cv::imread((*work_ / "rescaled" / "side.png").string()).size(), side.size());
}

TEST_F(Reconstruct, EvalBadInputs) {
  expect_clean_error("eval sim --truth sim", "head.obj");  // not a reconstruction
  expect_clean_error("eval missing_dir --truth sim", "missing_dir");
}

TEST_F(Reconstruct, HelpPrintsUsage) {
  for (const char* cmd : {"reconstruct --help", "eval --help"}) {
    const Result r = run(cmd, *work_);
    EXPECT_EQ(r.code, 0);
    EXPECT_NE(r.out.find("usage"), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace orthoface::app
