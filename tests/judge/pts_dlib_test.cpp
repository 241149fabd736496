// A .pts file as dlib's own 68-point predictor gives it, on a real photo, as
// `reconstruct --front-landmarks` input.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "judge/face_judge.h"
#include "tests/common/run_command.h"
#include "tests/common/test_data.h"
#include "vision/pts_io.h"

namespace orthoface::judge {
namespace {

namespace fs = std::filesystem;

TEST(DlibPts, APtsFromDlibsPredictorIsAcceptedByReconstruct) {
  const std::string front = testing::shared_data("frmdb_multiview/001/Img_33.JPG");
  const std::string side = testing::shared_data("frmdb_multiview/001/Img_53.JPG");
  if (front.empty() || !fs::exists(front) || !fs::exists(side))
    GTEST_SKIP() << "no ../shared/data/frmdb_multiview/001";
  if (!predictor_available()) GTEST_SKIP() << "no dlib predictor (libdlib-data)";
  const cv::Mat image = cv::imread(front, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  const auto face = FaceJudge().largest_face(image);
  ASSERT_TRUE(face);
  // The file as a dlib user writes it: shape.part(k) as "x y", pixel indices.
  const fs::path work = testing::temp_dir("dlib_pts");
  {
    std::ofstream out(work / "front.pts");
    out << "version: 1\nn_points: 68\n{\n";
    for (const cv::Point2d& p : face->points) out << p.x << " " << p.y << "\n";
    out << "}\n";
  }
  const vision::Ibug68 read = vision::read_pts((work / "front.pts").string());
  for (int k = 0; k < vision::kIbug68Count; ++k) {
    ASSERT_TRUE(read[k]) << k;
    EXPECT_EQ(*read[k], face->points[k] + cv::Point2d(0.5, 0.5));
  }
  const auto r = testing::run_orthoface(
      "reconstruct --front " + front + " --side " + side + " --front-landmarks front.pts --out rec",
      work);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(work / "rec" / "observation.json");
  const auto obs = nlohmann::json::parse(in);
  EXPECT_EQ(obs["front"]["features"]["eye_left_outer"]["method"], "user");
  EXPECT_NEAR(obs["front"]["features"]["eye_left_outer"]["x"].get<double>(),
              face->points[45].x + 0.5, 1e-9);
}

}  // namespace
}  // namespace orthoface::judge
