#include "capture/stereo_rig.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "capture/camera_model.h"
#include "sim/rig.h"
#include "tests/capture/same_camera.h"
#include "tests/common/test_data.h"

namespace orthoface::capture {
namespace {

namespace fs = std::filesystem;
using orthoface::testing::expect_same_camera;
using orthoface::testing::expect_same_pose;

RigCalibration sim_rig() {
  sim::RigOptions o;
  o.kind = sim::RigKind::Perspective;
  return sim::nominal_rig(o);
}

// A calibrated-looking rig: distortion, unequal intrinsics, the side camera a little off.
RigCalibration odd_rig() {
  RigCalibration rig = sim_rig();
  rig.front.distortion = {-0.1, 0.02, 0.001, -0.002, 0.003};
  rig.side.fx = 1500, rig.side.fy = 1510, rig.side.cx = 330.25, rig.side.cy = 236.5;
  rig.side.width = 800, rig.side.height = 600;
  sim::RigOptions o;
  o.kind = sim::RigKind::Perspective;
  o.side_error.yaw_deg = 2, o.side_error.pitch_deg = -1.5, o.side_error.roll_deg = 1;
  o.side_error.offset_mm = Eigen::Vector3d(3, -4, 5);
  rig.side.cam_from_head = sim::true_rig(o).side.cam_from_head;
  return rig;
}

// What OpenCV's stereo_calib sample keeps after cv::stereoCalibrate (its intrinsics.yml and
// extrinsics.yml in one file), written with cv::FileStorage as the sample does.
void write_like_opencv(const RigCalibration& rig, const fs::path& path, bool sample_names) {
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  auto k = [](const CameraModel& c) {
    return cv::Mat((cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1));
  };
  const Eigen::Isometry3d s_f = rig.side.cam_from_head * rig.front.cam_from_head.inverse();
  cv::Mat r, t;
  cv::eigen2cv(Eigen::Matrix3d(s_f.linear()), r);
  cv::eigen2cv(Eigen::Vector3d(s_f.translation()), t);
  const cv::Mat d = cv::Mat::zeros(1, 5, CV_64F);
  fs << (sample_names ? "M1" : "K1") << k(rig.front) << "D1" << d;
  fs << (sample_names ? "M2" : "K2") << k(rig.side) << "D2" << d;
  fs << "R" << r << "T" << t;
  if (sample_names)
    fs << "imageSize" << cv::Size(rig.front.width, rig.front.height);
  else
    fs << "image_width" << rig.front.width << "image_height" << rig.front.height;
}

TEST(StereoRig, OurRigRoundTripsThroughTheOpenCvForm) {
  const fs::path dir = testing::temp_dir("stereo_rig_round_trip");
  for (const RigCalibration& rig : {sim_rig(), odd_rig()}) {
    const std::string path = (dir / "stereo.yaml").string();
    write_rig(rig, path, RigFormat::OpenCvStereo);
    const RigCalibration back = read_rig(path);
    expect_same_camera(back.front, rig.front, 1e-9);
    expect_same_camera(back.side, rig.side, 1e-9);
    EXPECT_EQ(back.source, path);
  }
}

TEST(StereoRig, AFileAsOpenCvsSampleWritesItReadsAsTheSimRig) {
  const fs::path dir = testing::temp_dir("stereo_rig_opencv");
  const RigCalibration rig = sim_rig();
  const std::vector<Eigen::Vector3d> points = {
      {0, 0, 0}, {30, 40, 90}, {-60, -20, 70}, {75, 10, -20}, {-10, 100, 40}};
  for (bool sample_names : {true, false}) {
    const fs::path path = dir / (sample_names ? "sample.yml" : "named.xml");
    write_like_opencv(rig, path, sample_names);
    const RigCalibration back = read_rig(path.string());
    for (const Eigen::Vector3d& p : points) {
      EXPECT_LT((project(back.front, p) - project(rig.front, p)).norm(), 1e-6) << p.transpose();
      EXPECT_LT((project(back.side, p) - project(rig.side, p)).norm(), 1e-6) << p.transpose();
    }
    EXPECT_EQ(back.side.width, rig.front.width);
  }
}

TEST(StereoRig, HeadFrameIsTheOneCalibrateUses) {
  // The sim rig's cameras aim at the head origin from +z and +x: the derived frame is its own.
  const RigCalibration rig = sim_rig();
  const StereoAxes a = stereo_axes(rig.side.cam_from_head * rig.front.cam_from_head.inverse());
  expect_same_pose(a.front_from_head.inverse(), rig.front.cam_from_head.inverse(), 1e-9);
  EXPECT_NEAR(a.angle_deg, 90, 1e-9);
  EXPECT_NEAR(a.gap_mm, 0, 1e-9);
  EXPECT_NEAR(a.front_depth_mm, 1000, 1e-9);
  EXPECT_NEAR(a.side_depth_mm, 1000, 1e-9);
}

TEST(StereoRig, RigFromStereoRefusesBadPoses) {
  const RigCalibration rig = sim_rig();
  const Eigen::Isometry3d s_f = rig.side.cam_from_head * rig.front.cam_from_head.inverse();
  EXPECT_NO_THROW(rig_from_stereo(rig.front, rig.side, s_f));
  Eigen::Isometry3d bad = s_f;
  bad.linear() *= 1.01;
  EXPECT_THROW(rig_from_stereo(rig.front, rig.side, bad), std::invalid_argument);
  bad = Eigen::Isometry3d::Identity();
  bad.translation() = Eigen::Vector3d(-100, 0, 0);  // parallel axes
  EXPECT_THROW(rig_from_stereo(rig.front, rig.side, bad), std::invalid_argument);
  bad = s_f;
  bad.translation().x() = NAN;
  EXPECT_THROW(rig_from_stereo(rig.front, rig.side, bad), std::invalid_argument);
  CameraModel no_focal = rig.front;
  no_focal.fx = 0;
  EXPECT_THROW(rig_from_stereo(no_focal, rig.side, s_f), std::invalid_argument);
}

TEST(StereoRig, WritingAnOrthographicRigOrToAMissingFolderThrows) {
  const fs::path dir = testing::temp_dir("stereo_rig_write_bad");
  EXPECT_THROW(write_opencv_stereo(ideal_rig(640, 480, 1.6), (dir / "r.yaml").string()),
               std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "r.yaml"));
  EXPECT_THROW(write_rig(sim_rig(), (dir / "no" / "r.yaml").string(), RigFormat::OpenCvStereo),
               std::runtime_error);
  EXPECT_EQ(parse_rig_format("opencv"), RigFormat::OpenCvStereo);
  EXPECT_EQ(parse_rig_format("orthoface"), RigFormat::Orthoface);
  EXPECT_THROW(parse_rig_format("colmap"), std::invalid_argument);
}

// Each bad file gives one std::runtime_error naming the file and the field.
// A matrix whose size line is corrupt ("cols: cols: 3", found by fuzz_rig) made OpenCV allocate
// 17 GB; the line is refused as it is read (sizes: RigText.MatrixNodesAreChecked...).
TEST(StereoRig, CorruptMatrixSizesAreRefusedBeforeAllocating) {
  const std::string path =
      std::string(ORTHOFACE_SOURCE_DIR) + "/fuzz/corpus/rig/regress_corrupt_matrix_size.yaml";
  try {
    read_rig(path);
    ADD_FAILURE() << "read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 10: a mapping inside a value"), std::string::npos)
        << e.what();
  }
}

// OpenCV's YAML parser ran past 10 s on 267 bytes of nested brackets and never returned on other
// files of a few dozen bytes (found by fuzz_rig): rig files are read by capture/rig_text.h,
// which refuses them at once, naming the file and the line.
TEST(StereoRig, FilesThatHungOpenCvsParserAreRefusedNamingTheLine) {
  const fs::path dir = testing::temp_dir("rig_text");
  auto message = [](const std::string& path) {
    try {
      read_rig(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  const std::string corpus = std::string(ORTHOFACE_SOURCE_DIR) + "/fuzz/corpus/rig/";
  const std::string nested = corpus + "regress_nested_brackets.yaml";
  EXPECT_NE(message(nested).find(nested + ": line 4: byte 0x"), std::string::npos)
      << message(nested);
  const std::string unclosed = corpus + "regress_unclosed_brackets.yaml";
  EXPECT_NE(message(unclosed).find(unclosed + ": line 2: expected 'key: value'"), std::string::npos)
      << message(unclosed);
  std::ofstream(dir / "nested.yaml")
      << "%YAML:1.0\n---\nK1: " << std::string(9, '[') << "1" << std::string(9, ']') << "\n";
  EXPECT_NE(message((dir / "nested.yaml").string()).find("line 3: nested more than 8 deep"),
            std::string::npos)
      << message((dir / "nested.yaml").string());
  std::ofstream(dir / "huge.yaml") << "%YAML:1.0\n---\n# " << std::string(1 << 20, 'x') << "\n";
  EXPECT_NE(message((dir / "huge.yaml").string()).find("over 1 MiB"), std::string::npos);
  // Our own rig and comments in UTF-8 still read.
  write_rig(ideal_rig(64, 48, 1.0), (dir / "ok.yaml").string());
  { std::ofstream(dir / "ok.yaml", std::ios::app) << "# Kamera f\xc3\xbcr vorne\n"; }
  EXPECT_NO_THROW(read_rig((dir / "ok.yaml").string()));
}

TEST(StereoRig, BadFilesThrowNamingTheFileAndField) {
  const fs::path dir = testing::temp_dir("stereo_rig_bad");
  const std::string k =
      "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 1600., 0., "
      "320., 0., 1600., 240., 0., 0., 1. ]\n";
  const std::string d =
      "!!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n   data: [ 0., 0., "
      "0., 0., 0. ]\n";
  const std::string r =
      "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 0., 0., "
      "1., 0., 1., 0., -1., 0., 0. ]\n";
  const std::string t =
      "!!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ -1000., "
      "0., 1000. ]\n";
  auto file = [&](const std::map<std::string, std::string>& replace,
                  const std::vector<std::string>& drop) {
    std::map<std::string, std::string> f = {{"image_size", "[ 640, 480 ]\n"},
                                            {"K1", k},
                                            {"D1", d},
                                            {"K2", k},
                                            {"D2", d},
                                            {"R", r},
                                            {"T", t}};
    for (const auto& [key, v] : replace) f[key] = v;
    for (const auto& key : drop) f.erase(key);
    std::string text = "%YAML:1.0\n---\n";
    for (const auto& [key, v] : f) text += key + ": " + v;
    return text;
  };
  const fs::path good = dir / "good.yaml";
  std::ofstream(good) << file({}, {});
  EXPECT_NO_THROW(read_rig(good.string()));
  const std::string bad_r_data = "data: [ 0., 0., 1., 0., 1., 0., 1., 0., 0. ]";  // det -1
  const std::vector<std::tuple<std::string, std::string, std::vector<std::string>, std::string>>
      cases = {
          {"K2", "", {"K2"}, "K2 (or M2): missing"},
          {"D1", "", {"D1"}, "D1: missing"},
          {"R", "", {"R"}, "R: missing"},
          {"T", "", {"T"}, "T: missing"},
          {"image_size", "", {"image_size"}, "image_size: missing"},
          {"image_size", "[ 640 ]\n", {}, "image_size: must be [width, height]"},
          {"image_size", "[ 0, 480 ]\n", {}, "image_size: 0x480"},
          {"K1",
           "!!opencv-matrix\n   rows: 2\n   cols: 3\n   dt: d\n   data: [ 1., 0., 1., 0., 1., 1. "
           "]\n",
           {},
           "K1: must be 3x3"},
          {"K1",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 1600., 5., 320., 0., "
           "1600., 240., 0., 0., 1. ]\n",
           {},
           "K1: must be [fx 0 cx"},
          {"K1",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ .nan, 0., 320., 0., "
           "1600., 240., 0., 0., 1. ]\n",
           {},
           "K1: has a non-finite value"},
          {"K2",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 1e9, 0., 320., 0., "
           "1e9, 240., 0., 0., 1. ]\n",
           {},
           "K2/D2"},
          {"D2",
           "!!opencv-matrix\n   rows: 1\n   cols: 3\n   dt: d\n   data: [ 0., 0., 0. ]\n",
           {},
           "D2: must hold 4 or more"},
          {"D2",
           "!!opencv-matrix\n   rows: 1\n   cols: 8\n   dt: d\n   data: [ 0., 0., 0., 0., 0., "
           "0.1, 0., 0. ]\n",
           {},
           "D2: coefficient 6"},
          {"R",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   " + bad_r_data + "\n",
           {},
           "R: is not a rotation"},
          {"R",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 0., 0., 2., 0., 1., "
           "0., -1., 0., 0. ]\n",
           {},
           "R: is not a rotation"},
          {"R",
           "!!opencv-matrix\n   rows: 2\n   cols: 2\n   dt: d\n   data: [ 1., 0., 0., 1. ]\n",
           {},
           "R: must be a 3x3"},
          {"T",
           "!!opencv-matrix\n   rows: 2\n   cols: 1\n   dt: d\n   data: [ 1., 0. ]\n",
           {},
           "T: must hold 3"},
          {"T",
           "!!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ -1000., .inf, 1000. ]\n",
           {},
           "T: has a non-finite"},
          {"T",
           "!!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ -1e9, 0., 1e9 ]\n",
           {},
           "baseline"},
          // The side camera 400 mm higher: its axis passes far above the front camera's.
          {"T",
           "!!opencv-matrix\n   rows: 3\n   cols: 1\n   dt: d\n   data: [ -1000., 400., 1000. ]\n",
           {},
           "apart"},
          // The side camera looking along the front camera's axis.
          {"R",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 1., 0., 0., 0., 1., "
           "0., 0., 0., 1. ]\n",
           {},
           "deg"},
          // Axes crossing behind the side camera (it looks away from the head).
          {"R",
           "!!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 0., 0., -1., 0., 1., "
           "0., 1., 0., 0. ]\n",
           {},
           "behind"},
      };
  for (size_t i = 0; i < cases.size(); ++i) {
    const auto& [key, value, drop, needle] = cases[i];
    const fs::path path = dir / ("bad" + std::to_string(i) + ".yaml");
    std::map<std::string, std::string> rep;
    if (!value.empty()) rep[key] = value;
    std::ofstream(path) << file(rep, drop);
    try {
      read_rig(path.string());
      ADD_FAILURE() << "no error for case " << i << " (" << needle << ")";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path.string()), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << "case " << i << ": " << what;
    }
  }
  // A written file whose head-frame pose was damaged.
  const fs::path ours = dir / "ours.yaml";
  write_rig(sim_rig(), ours.string(), RigFormat::OpenCvStereo);
  std::ifstream in(ours);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t at = text.find("\northoface_cam1_from_head:");
  ASSERT_NE(at, std::string::npos);
  const size_t data = text.find("data: [", at) + 7;
  text.insert(text.find_first_of("-0123456789", data), "2");  // R00 1 -> 21: not a rotation
  const fs::path damaged = dir / "damaged.yaml";
  std::ofstream(damaged) << text;
  EXPECT_THROW(read_rig(damaged.string()), std::runtime_error);
  EXPECT_THROW(read_opencv_stereo((dir / "none.yaml").string()), std::runtime_error);
}

}  // namespace
}  // namespace orthoface::capture
