// `orthoface simulate`, run as a separate process like scripts do.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "mesh/mesh_io.h"
#include "sim/truth_json.h"
#include "tests/common/run_command.h"
#include "tests/common/scene_photo.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

using ProcessResult = testing::CommandResult;
using testing::slurp;

// Runs `orthoface <args>` with stdout / stderr captured in `work`.
ProcessResult run(const std::string& args, const fs::path& work) {
  return testing::run_orthoface(args, work);
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

std::vector<std::string> files_in(const fs::path& dir) {
  std::vector<std::string> names;
  if (!fs::is_directory(dir)) return names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(SimulateCommand, WritesTheFullTruthFolder) {
  const fs::path work = testing::temp_dir("app_simulate_ok");
  const ProcessResult r =
      run("simulate --subject 1 --out sim1 --size 320x240 --px-per-mm 0.8", work);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(count_lines(r.out), 1) << r.out;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const fs::path dir = work / "sim1";
  const std::vector<std::string> expected = {"background.png", "background_side.png",
                                             "front.png",      "front_mask.png",
                                             "landmarks.json", "rig.yaml",
                                             "side.png",       "side_mask.png",
                                             "truth.mtl",      "truth.obj",
                                             "truth.png"};
  EXPECT_EQ(files_in(dir), expected);
  const cv::Mat front = cv::imread((dir / "front.png").string());
  ASSERT_EQ(front.size(), cv::Size(320, 240));
  const sim::Truth truth = sim::read_truth_json((dir / "landmarks.json").string());
  EXPECT_EQ(truth.subject, "sim seed 1");
  EXPECT_EQ(truth.landmarks.size(), 30u);
  // rig.yaml is the nominal rig, in the format `reconstruct --rig` reads.
  const capture::RigCalibration rig = capture::read_rig((dir / "rig.yaml").string());
  EXPECT_TRUE(rig.side.cam_from_head.isApprox(truth.nominal_rig.side.cam_from_head, 1e-12));
  EXPECT_DOUBLE_EQ(rig.front.fx, 0.8);
  // The nose tip is on the head in both photos (mask) at the row the truth gives, in both views.
  const auto& nose = truth.landmarks.at("nose_tip");
  EXPECT_TRUE(nose.visible_front);
  EXPECT_TRUE(truth.landmarks.at("eye_left_outer").visible_side);    // side camera at +x
  EXPECT_FALSE(truth.landmarks.at("eye_right_outer").visible_side);  // behind the head
  EXPECT_NEAR(nose.front_px.y(), nose.side_px.y(), 1e-9);
  const cv::Mat mask = cv::imread((dir / "side_mask.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(mask.at<uchar>(int(nose.side_px.y()), int(nose.side_px.x()) + 1), 255);
  const mesh::TriMesh mesh = mesh::read_mesh((dir / "truth.obj").string());
  EXPECT_GT(mesh.triangles.size(), 1000u);
  EXPECT_FALSE(mesh.texture.empty());
  EXPECT_EQ(files_in(dir).size(), expected.size());  // no scratch or .tmp files left
  // Running again into the same folder replaces the files.
  EXPECT_EQ(run("simulate --subject 1 --out sim1 --size 320x240", work).code, 0);
}

TEST(SimulateCommand, OptionsChangeThePhotos) {
  const fs::path work = testing::temp_dir("app_simulate_options");
  ASSERT_EQ(run("simulate --subject 2 --out a --size 200x150 --px-per-mm 0.5", work).code, 0);
  const ProcessResult r =
      run("simulate --subject 2 --out b --size 200x150 --rig perspective --focal 500 "
          "--noise 4 --blur 1 --background cluttered --light 0.4,0.8,1,0,-1 "
          "--misalign 2,3 --seed 5",
          work);
  ASSERT_EQ(r.code, 0) << r.err;
  const cv::Mat a = cv::imread((work / "a" / "front.png").string());
  const cv::Mat b = cv::imread((work / "b" / "front.png").string());
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1) / a.total(), 10.0);
  const sim::Truth t = sim::read_truth_json((work / "b" / "landmarks.json").string());
  EXPECT_EQ(t.options.kind, sim::RigKind::Perspective);
  EXPECT_EQ(t.options.background, sim::BackgroundKind::Cluttered);
  EXPECT_FALSE(t.true_rig.front.cam_from_head.isApprox(t.nominal_rig.front.cam_from_head, 1e-6));
}

// --background photo:FILE: each camera sees its part of the photograph; landmarks.json says which.
TEST(SimulateCommand, BackgroundPhotoPutsTheHeadInAScene) {
  const fs::path work = testing::temp_dir("app_simulate_photo");
  testing::write_scene_photo((work / "room.png").string(), 5);
  const ProcessResult r = run("simulate --subject 2 --out s --background photo:room.png", work);
  ASSERT_EQ(r.code, 0) << r.err;
  const cv::Mat front = cv::imread((work / "s" / "front.png").string());
  const cv::Mat plate = cv::imread((work / "s" / "background.png").string());
  const cv::Mat side_plate = cv::imread((work / "s" / "background_side.png").string());
  cv::Scalar mean, sd;
  cv::meanStdDev(plate, mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 60.0);  // a scene, not a plain colour
  EXPECT_GT(cv::norm(plate, side_plate, cv::NORM_L1) / plate.total(), 10.0);
  EXPECT_GT(cv::norm(front, plate, cv::NORM_L1) / front.total(), 1.0);  // the head stands in it
  const sim::Truth t = sim::read_truth_json((work / "s" / "landmarks.json").string());
  EXPECT_EQ(t.options.background, sim::BackgroundKind::Photo);
  EXPECT_EQ(t.options.background_photo, "room.png");
}

// --mouth opens the sim head's mouth: the chin lower by the opening, the face above the lips
// where it was.
TEST(SimulateCommand, MouthOpensTheJaw) {
  const fs::path work = testing::temp_dir("app_simulate_mouth");
  ASSERT_EQ(run("simulate --subject 2 --out shut", work).code, 0);
  const ProcessResult r = run("simulate --subject 2 --out open --mouth 8", work);
  ASSERT_EQ(r.code, 0) << r.err;
  const sim::Truth shut = sim::read_truth_json((work / "shut" / "landmarks.json").string());
  const sim::Truth open = sim::read_truth_json((work / "open" / "landmarks.json").string());
  EXPECT_NEAR(open.landmarks.at("chin").xyz_mm.y(), shut.landmarks.at("chin").xyz_mm.y() - 8, 1e-6);
  EXPECT_LT((open.landmarks.at("nose_tip").xyz_mm - shut.landmarks.at("nose_tip").xyz_mm).norm(),
            1e-9);
}

TEST(SimulateCommand, HelpListsTheFlags) {
  const fs::path work = testing::temp_dir("app_simulate_help");
  const ProcessResult r = run("simulate --help", work);
  EXPECT_EQ(r.code, 0);
  for (const char* flag : {"--subject", "--out", "--rig", "--size", "--noise", "--blur",
                           "--background", "--light", "--scan", "--mouth"})
    EXPECT_NE(r.out.find(flag), std::string::npos) << flag;
}

// Every bad input: one "error:" line, non-zero exit, nothing written.
void expect_clean_failures(const std::vector<std::string>& cases, const std::string& name) {
  const fs::path work = testing::temp_dir(name);
  std::ofstream(work / "a_file") << "keep";
  fs::create_directories(work / "corrupt" / "lee_perry_smith_head");  // a scan that is garbage
  std::ofstream(work / "corrupt" / "lee_perry_smith_head" / "LeePerrySmith.obj")
      << "v 1 2\nf 9 9 9\n";
  for (const std::string& c : cases) {
    const ProcessResult r = run(c, work);
    EXPECT_NE(r.code, 0) << c;
    EXPECT_EQ(count_lines(r.err), 1) << c << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << c << "\n" << r.err;
    EXPECT_FALSE(fs::exists(work / "out")) << c;
    EXPECT_EQ(slurp(work / "a_file"), "keep") << c;
  }
}

TEST(SimulateCommand, BadArgumentsGiveOneErrorLineAndNoFiles) {
  expect_clean_failures(
      {
          "simulate --subject abc --out out",
          "simulate --subject -3 --out out",
          "simulate --subject 1.5 --out out",
          "simulate --subject 1 --out a_file",
          "simulate --subject 1 --out out --size 0x0",
          "simulate --subject 1 --out out --size 100000x100000",
          "simulate --subject 1 --out out --size 640",
          "simulate --subject 1 --out out --frobnicate",
          "simulate --subject 1 --out out extra_argument",
      },
      "app_simulate_bad_args");
}

TEST(SimulateCommand, BadSubjectOrScanGivesOneErrorLineAndNoFiles) {
  expect_clean_failures(
      {
          "simulate --subject 1",
          "simulate --out out",
          "simulate --subject 1 --scan lee-perry-smith --out out",
          "simulate --scan nobody --out out",
          "simulate --scan lee-perry-smith --data /nonexistent --out out",
          "simulate --scan lee-perry-smith --data corrupt --out out",
      },
      "app_simulate_bad_subject");
}

TEST(SimulateCommand, BadValuesGiveOneErrorLineAndNoFiles) {
  expect_clean_failures(
      {
          "simulate --subject 1 --out out --rig fisheye",
          "simulate --subject 1 --out out --noise -2",
          "simulate --subject 1 --out out --blur lots",
          "simulate --subject 1 --out out --background jungle",
          "simulate --subject 1 --out out --background photo:",
          "simulate --subject 1 --out out --background photo:missing.png",
          "simulate --subject 1 --out out --background photo:a_file",
          "simulate --subject 1 --out out --light 1",
          "simulate --subject 1 --out out --light 1,0.5,0,0,0",
          "simulate --subject 1 --out out --misalign 45",
          "simulate --subject 1 --out out --distance 10 --rig perspective",
          "simulate --subject 1 --out out --mouth 30",
          "simulate --subject 1 --out out --mouth wide",
      },
      "app_simulate_bad_values");
}

TEST(SimulateCommand, ScanRendersWhenTheDataIsPresent) {
  const std::string dir = testing::shared_data("lee_perry_smith_head");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/lee_perry_smith_head";
  const fs::path work = testing::temp_dir("app_simulate_scan");
  const ProcessResult r =
      run("simulate --scan lee-perry-smith --data '" + std::string(ORTHOFACE_DATA_DIR) +
              "' --out scan --size 320x240 --px-per-mm 0.8",
          work);
  ASSERT_EQ(r.code, 0) << r.err;
  const cv::Mat mask =
      cv::imread((work / "scan" / "front_mask.png").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_GT(cv::countNonZero(mask), 0.1 * mask.total());
}

}  // namespace
}  // namespace orthoface::app
