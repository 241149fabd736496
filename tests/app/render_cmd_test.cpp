// `orthoface render`, run as a separate process on a reconstruction folder made here.
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "mesh/mesh_io.h"
#include "render/image_metrics.h"
#include "render/renderer.h"
#include "render/shapes.h"
#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

using testing::slurp;

// Exit code of `orthoface <args>` run in `work`; stdout / stderr land in work/out.txt, err.txt.
int run(const std::string& args, const fs::path& work) {
  return testing::run_orthoface(args, work).code;
}

// A reconstruction folder of a textured ellipsoid seen by the ideal rig; returns the textured
// mesh (the truth) and fills `rig`.
mesh::TriMesh make_folder(const fs::path& dir, capture::RigCalibration& rig) {
  fs::create_directories(dir);
  mesh::TriMesh m = render::uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 32, 64, 512);
  rig = capture::ideal_rig(320, 240, 1.0);
  render::Renderer r;
  cv::imwrite((dir / "front.png").string(), r.render(m, rig.front).image);
  cv::imwrite((dir / "side.png").string(), r.render(m, rig.side).image);
  capture::write_rig(rig, (dir / "rig.yaml").string());
  mesh::write_mesh(m, (dir / "head.obj").string());
  return m;
}

TEST(RenderCommand, RendersANewViewCloseToTheTruth) {
  const fs::path work = testing::temp_dir("app_render");
  capture::RigCalibration rig;
  const mesh::TriMesh truth_mesh = make_folder(work / "rec", rig);
  ASSERT_EQ(run("render rec --yaw 40 --blend weighted -o view.png", work), 0)
      << slurp(work / "err.txt");
  const cv::Mat view = cv::imread((work / "view.png").string());
  ASSERT_EQ(view.size(), cv::Size(320, 240));
  const render::RenderResult truth =
      render::render_once(truth_mesh, capture::camera_at(rig.front, 40 * M_PI / 180, 0, 1000));
  EXPECT_GT(render::psnr(truth.image, view, truth.mask), 30.0);

  ASSERT_EQ(
      run("render rec --yaw -30 --pitch 10 --size 160x120 --background transparent -o t.png", work),
      0)
      << slurp(work / "err.txt");
  const cv::Mat t = cv::imread((work / "t.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(t.type(), CV_8UC4);
  EXPECT_EQ(t.size(), cv::Size(160, 120));
  EXPECT_EQ(t.at<cv::Vec4b>(0, 0)[3], 0);      // corner: background
  EXPECT_EQ(t.at<cv::Vec4b>(60, 80)[3], 255);  // centre: the head
}

TEST(RenderCommand, TurntableAndExports) {
  const fs::path work = testing::temp_dir("app_render_turntable");
  capture::RigCalibration rig;
  make_folder(work / "rec", rig);
  ASSERT_EQ(run("render rec --turntable 3 -o sheet.png --export head.glb", work), 0)
      << slurp(work / "err.txt");
  for (const char* f :
       {"sheet.png", "sheet_yaw-090.png", "sheet_yaw+000.png", "sheet_yaw+090.png", "head.glb"})
    EXPECT_TRUE(fs::exists(work / f)) << f;
  ASSERT_EQ(run("render rec --export head.obj", work), 0) << slurp(work / "err.txt");
  EXPECT_TRUE(fs::exists(work / "head.png"));
  EXPECT_EQ(mesh::read_mesh((work / "head.obj").string()).triangles.size(), 2u * 64 * 31);
}

TEST(RenderCommand, UnseenSideUsesTheLandmarksMidPlane) {
  const fs::path work = testing::temp_dir("app_render_mirror");
  capture::RigCalibration rig;
  make_folder(work / "rec", rig);
  std::ofstream(work / "rec" / "landmarks.json")
      << R"({"landmarks": {"eye_left_outer": {"xyz_mm": [40, 20, 60]},
           "eye_right_outer": {"xyz_mm": [-40, 20, 60]}, "mouth_left": {"xyz_mm": [25, -50, 70]},
           "mouth_right": {"xyz_mm": [-25, -50, 70]}}})";
  ASSERT_EQ(run("render rec --yaw -80 --no-float --unseen front -o plain.png", work), 0)
      << slurp(work / "err.txt");
  EXPECT_NE(slurp(work / "out.txt").find("unseen side: front"), std::string::npos);
  const cv::Mat plain = cv::imread((work / "plain.png").string());
  for (const char* mode : {"texture", "view"}) {
    ASSERT_EQ(
        run(std::string("render rec --yaw -80 --no-float --unseen ") + mode + " -o mirrored.png",
            work),
        0)
        << slurp(work / "err.txt");
    EXPECT_NE(slurp(work / "out.txt").find(std::string("unseen side: ") + mode), std::string::npos);
    const cv::Mat mirrored = cv::imread((work / "mirrored.png").string());
    ASSERT_EQ(plain.size(), mirrored.size());
    EXPECT_GT(cv::norm(plain, mirrored, cv::NORM_L1) / plain.total(), 1.0) << mode;
  }
  // The default is the mirrored view.
  ASSERT_EQ(run("render rec --yaw -80 --no-float -o default.png", work), 0);
  EXPECT_NE(slurp(work / "out.txt").find("unseen side: view"), std::string::npos);
  // A broken landmarks.json stops a render that needs it with one error line; --unseen front
  // never reads it.
  std::ofstream(work / "rec" / "landmarks.json") << "{\"landmarks\": [";
  EXPECT_NE(run("render rec --yaw -80 -o broken.png", work), 0);
  const std::string err = slurp(work / "err.txt");
  EXPECT_EQ(err.rfind("error: ", 0), 0u) << err;
  EXPECT_NE(err.find("landmarks.json"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(work / "broken.png"));
  EXPECT_EQ(run("render rec --yaw -80 --unseen front -o plain2.png", work), 0)
      << slurp(work / "err.txt");
  // Without landmarks.json the default falls back to the front photo and says so.
  fs::remove(work / "rec" / "landmarks.json");
  ASSERT_EQ(run("render rec --yaw -80 -o fallback.png", work), 0) << slurp(work / "err.txt");
  EXPECT_NE(slurp(work / "out.txt").find("unseen side: front"), std::string::npos);
  // The folder's own files are never replaced by an output.
  for (const char* own : {"rec/front.png", "rec/side.png", "./rec/../rec/front.png"}) {
    const auto before = fs::last_write_time(work / own);
    EXPECT_EQ(run(std::string("render rec --yaw 10 -o ") + own, work), 1) << own;
    EXPECT_NE(slurp(work / "err.txt").find("is the reconstruction's own"), std::string::npos)
        << slurp(work / "err.txt");
    EXPECT_EQ(fs::last_write_time(work / own), before) << own;
  }
  EXPECT_EQ(run("render rec --export rec/head.obj", work), 1);
  EXPECT_NE(slurp(work / "err.txt").find("head.obj"), std::string::npos);
  // More than 181 views are closer than a degree: each still gets a file of its own.
  fs::create_directories(work / "turn");
  ASSERT_EQ(run("render rec --turntable 200 --size 40x30 --no-float --head face --background "
                "black -o turn/t.png",
                work),
            0)
      << slurp(work / "err.txt");
  EXPECT_EQ(std::distance(fs::directory_iterator(work / "turn"), fs::directory_iterator()), 201);
  EXPECT_TRUE(fs::exists(work / "turn/t_yaw-090.0.png"));
  // An explicit --unseen that needs the mid-plane is refused instead.
  EXPECT_EQ(run("render rec --yaw -80 --unseen texture -o refused.png", work), 1);
  EXPECT_EQ(slurp(work / "err.txt"),
            "error: --unseen texture: rec has no landmarks.json with left / right feature pairs\n");
  EXPECT_FALSE(fs::exists(work / "refused.png"));
}

// By default a view is drawn into the front photo's own scene, the head removed from it.
TEST(RenderCommand, DrawsTheViewIntoThePhotosScene) {
  const fs::path work = testing::temp_dir("app_render_scene");
  capture::RigCalibration rig;
  make_folder(work / "rec", rig);
  render::Renderer r;
  render::RenderOptions ro;
  ro.background = cv::Scalar(40, 120, 200);  // a room's colour behind the head
  const mesh::TriMesh m = render::uv_ellipsoid({0, 0, 0}, {70, 100, 85}, 32, 64, 512);
  cv::imwrite((work / "rec" / "front.png").string(), r.render(m, rig.front, ro).image);
  ASSERT_EQ(run("render rec --yaw 60 -o scene.png", work), 0) << slurp(work / "err.txt");
  ASSERT_EQ(run("render rec --yaw 60 --background black --head face -o black.png", work), 0)
      << slurp(work / "err.txt");
  const cv::Mat scene = cv::imread((work / "scene.png").string());
  const cv::Mat black = cv::imread((work / "black.png").string());
  EXPECT_EQ(scene.at<cv::Vec3b>(5, 5), cv::Vec3b(40, 120, 200));
  EXPECT_EQ(black.at<cv::Vec3b>(5, 5), cv::Vec3b(0, 0, 0));
  // The head itself is the same view in both.
  EXPECT_LT(cv::norm(scene.at<cv::Vec3b>(120, 160), black.at<cv::Vec3b>(120, 160)), 3);
}

TEST(RenderCommand, BadInputGivesOneErrorLine) {
  const fs::path work = testing::temp_dir("app_render_bad");
  capture::RigCalibration rig;
  make_folder(work / "rec", rig);
  fs::create_directories(work / "empty");
  for (const std::string args :
       {"render missing --yaw 10 -o a.png", "render empty --yaw 10 -o a.png",
        "render rec --yaw 200 -o a.png", "render rec --yaw 10 --size 0x0 -o a.png",
        "render rec --yaw 10 --size 100000x100 -o a.png",
        "render rec --yaw 10 --background transparent -o a.jpg", "render rec --yaw 10",
        "render rec --yaw 10 --blend sharp -o a.png", "render rec --yaw 10 -o nodir/a.png",
        "render rec --export head.stl", "render rec --yaw abc -o a.png",
        "render rec --yaw 10 --unseen sideways -o a.png",
        "render rec --yaw 10 --head shoulders -o a.png",
        "render rec --yaw 10 --unseen texture -o a.png"}) {  // no landmarks.json: no mid-plane
    EXPECT_NE(run(args, work), 0) << args;
    const std::string err = slurp(work / "err.txt");
    EXPECT_EQ(err.rfind("error: ", 0), 0u) << args << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
    EXPECT_FALSE(fs::exists(work / "a.png")) << args;
    EXPECT_FALSE(fs::exists(work / "a.jpg")) << args;
  }
  ASSERT_EQ(run("render --help", work), 0);
  EXPECT_NE(slurp(work / "out.txt").find("--blend"), std::string::npos);
  EXPECT_NE(slurp(work / "out.txt").find("--unseen"), std::string::npos);
}

}  // namespace
}  // namespace orthoface::app
