#include "vision/pts_io.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/common/test_data.h"
#include "vision/ibug68.h"
#include "vision/landmarks.h"
#include "vision/observe.h"

namespace orthoface::vision {
namespace {

namespace fs = std::filesystem;

Ibug68 some_points() {
  Ibug68 p;
  for (int k = 0; k < kIbug68Count; ++k)
    if (k % 7 != 3) p[k] = cv::Point2d(100.25 + 3.1 * k, 200.5 + std::sin(k) * 40.0 + 1e-9 * k);
  return p;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Pts, RoundTripKeepsPointsAndMissingOnes) {
  const fs::path dir = testing::temp_dir("pts_round_trip");
  const Ibug68 p = some_points();
  write_pts(p, (dir / "a.pts").string());
  const Ibug68 back = read_pts((dir / "a.pts").string());
  for (int k = 0; k < kIbug68Count; ++k) {
    ASSERT_EQ(back[k].has_value(), p[k].has_value()) << k;
    if (p[k]) {
      EXPECT_EQ(*back[k], *p[k]) << k;
    }
  }
  const std::string text = slurp(dir / "a.pts");
  EXPECT_EQ(text.rfind("version: 1\nn_points: 68\n{\n", 0), 0u);
  EXPECT_NE(text.find("\n-1 -1\n"), std::string::npos);
  EXPECT_EQ(text.substr(text.size() - 2), "}\n");
}

TEST(Pts, FileCoordinatesArePixelIndices) {
  const fs::path dir = testing::temp_dir("pts_convention");
  std::string text = "version: 1\r\nn_points:  68\n\n{\n";
  for (int k = 0; k < kIbug68Count; ++k) text += k == 5 ? "-1 -1\n" : "10 20.5\n";
  std::ofstream(dir / "b.pts") << text << "}";
  const Ibug68 p = read_pts((dir / "b.pts").string());
  EXPECT_FALSE(p[5]);
  ASSERT_TRUE(p[0]);
  EXPECT_EQ(*p[0], cv::Point2d(10.5, 21.0));  // capture convention: pixel centre = index + 0.5
}

// Every malformed file: one std::runtime_error naming the file and the problem.
TEST(Pts, MalformedFilesThrowNamingTheFileAndProblem) {
  const fs::path dir = testing::temp_dir("pts_bad");
  std::string points;
  for (int k = 0; k < kIbug68Count; ++k) points += "1 2\n";
  const std::string ok_head = "version: 1\nn_points: 68\n{\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "empty"},
      {"n_points: 68\n{\n" + points + "}\n", "bad header"},
      {"version: 2\nn_points: 68\n{\n" + points + "}\n", "bad header"},
      {"version: 1\n{\n" + points + "}\n", "n_points"},
      {"version: 1\nn_points: 5\n{\n1 2\n1 2\n1 2\n1 2\n1 2\n}\n", "only the 68-point"},
      {"version: 1\nn_points: 68\n" + points + "}\n", "opening brace"},
      {ok_head + points, "closing brace"},
      {ok_head + "1 2\n1 2\n}\n", "only 2 points"},
      {ok_head + points + "1 2\n}\n", "more than 68"},
      {ok_head + "1 x\n" + points.substr(4) + "}\n", "two numbers"},
      {ok_head + "1\n" + points.substr(4) + "}\n", "two numbers"},
      {ok_head + "1 2 3\n" + points.substr(4) + "}\n", "two numbers"},
      {ok_head + "nan 2\n" + points.substr(4) + "}\n", "not finite"},
      {ok_head + "1 inf\n" + points.substr(4) + "}\n", "not finite"},
      {ok_head + "1 1e999\n" + points.substr(4) + "}\n", "not finite"},
      {ok_head + points + "}\nextra\n", "after the closing brace"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const fs::path path = dir / ("bad" + std::to_string(i) + ".pts");
    std::ofstream(path) << cases[i].first;
    try {
      read_pts(path.string());
      ADD_FAILURE() << "no error for case " << i;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(path.string()), std::string::npos) << what;
      EXPECT_NE(what.find(cases[i].second), std::string::npos) << "case " << i << ": " << what;
    }
  }
  EXPECT_THROW(read_pts((dir / "missing.pts").string()), std::runtime_error);
}

TEST(Pts, WritingBadPointsThrowsAndWritesNothing) {
  const fs::path dir = testing::temp_dir("pts_write_bad");
  Ibug68 p = some_points();
  p[3] = cv::Point2d(NAN, 1);
  EXPECT_THROW(write_pts(p, (dir / "a.pts").string()), std::invalid_argument);
  p[3] = cv::Point2d(-0.5, -0.5);  // the file's -1 -1
  EXPECT_THROW(write_pts(p, (dir / "a.pts").string()), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "a.pts"));
  EXPECT_THROW(write_pts(some_points(), (dir / "no" / "a.pts").string()), std::runtime_error);
}

TEST(Pts, PointsOutsideTheImageAreRefused) {
  Ibug68 p;
  p[0] = cv::Point2d(0, 0);
  p[1] = cv::Point2d(640, 480);
  EXPECT_NO_THROW(check_pts_in_image(p, 640, 480, "f.pts"));
  p[2] = cv::Point2d(641, 10);
  try {
    check_pts_in_image(p, 640, 480, "f.pts");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("f.pts: point 2"), std::string::npos) << e.what();
  }
  p[2] = cv::Point2d(10, NAN);
  EXPECT_THROW(check_pts_in_image(p, 640, 480, "f.pts"), std::invalid_argument);
}

TEST(Ibug68, MappingIsConsistentBothWays) {
  for (const auto& [name, k] : kIbug68Landmarks) {
    EXPECT_TRUE(is_landmark_name(name)) << name;
    EXPECT_EQ(ibug68_index(name), k);
    // iBUG's image-left points are the subject's right: the mirror has the mirrored index.
    EXPECT_GE(ibug68_index(mirrored_name(name)), 0) << name;
  }
  EXPECT_EQ(ibug68_index("eye_left_outer"), 45);
  EXPECT_EQ(ibug68_index("eye_right_outer"), 36);
  EXPECT_EQ(ibug68_index("forehead_top"), -1);
  EXPECT_THROW(ibug68_index("left_eye"), std::invalid_argument);
  const Ibug68 p = some_points();
  const auto named = named_from_ibug68(p);
  std::map<std::string, Feature2d> features;
  for (const auto& [name, q] : named) features[name].px = q;
  const Ibug68 back = ibug68_from_named(features);
  for (const auto& [name, k] : kIbug68Landmarks) {
    ASSERT_EQ(back[k].has_value(), p[k].has_value()) << name;
    if (p[k]) {
      EXPECT_EQ(*back[k], *p[k]);
    }
  }
  for (int k = 0; k < kIbug68Count; ++k)
    if (back[k]) {
      EXPECT_TRUE(p[k]);
    }
  // Derived points: eye centres need all six eye points, the chin lip 57 and chin 8.
  Ibug68 all;
  for (int k = 0; k < kIbug68Count; ++k) all[k] = cv::Point2d(k, 2 * k);
  const auto full = named_from_ibug68(all);
  EXPECT_EQ(full.size(), kIbug68Landmarks.size() + 3);
  EXPECT_EQ(full.at("eye_right_center"), cv::Point2d(38.5, 77));
  EXPECT_EQ(full.at("eye_left_center"), cv::Point2d(44.5, 89));
  all[40].reset();
  EXPECT_FALSE(named_from_ibug68(all).count("eye_right_center"));
}

TEST(Ibug68, NonFinitePointsAreRefused) {
  Ibug68 p;
  p[8] = cv::Point2d(INFINITY, 0);
  EXPECT_THROW(named_from_ibug68(p), std::invalid_argument);
  std::map<std::string, Feature2d> f;
  f["nose_tip"].px = cv::Point2d(NAN, 1);
  EXPECT_THROW(ibug68_from_named(f), std::invalid_argument);
  f["nose_tip"].px = cv::Point2d(1, 1);
  f["forehead_top"].px = cv::Point2d(NAN, 1);  // no iBUG point: ignored
  EXPECT_TRUE(ibug68_from_named(f)[30]);
}

TEST(ObserveOptions, UserLandmarksMustBeNamedFiniteAndInTheImage) {
  ObserveOptions o;
  o.front_landmarks["nose_tip"] = cv::Point2d(10, 10);
  EXPECT_NO_THROW(o.check());
  o.front_landmarks["nose"] = cv::Point2d(10, 10);
  EXPECT_THROW(o.check(), std::invalid_argument);
  o.front_landmarks.erase("nose");
  o.front_landmarks["chin"] = cv::Point2d(10, NAN);
  EXPECT_THROW(o.check(), std::invalid_argument);
  o.front_landmarks["chin"] = cv::Point2d(10, 1000);
  const cv::Mat img(100, 80, CV_8UC3, cv::Scalar(128, 128, 128));
  EXPECT_THROW(observe_front(img, o), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::vision
