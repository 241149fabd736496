#include "judge/face_judge.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"
#include "tests/common/test_data.h"

namespace orthoface::judge {
namespace {

// A plausible 68-point layout: jaw arc, brows, nose, eyes, mouth (only the geometry matters).
Landmarks68 layout() {
  Landmarks68 p;
  for (int k = 0; k <= 16; ++k) {
    const double a = M_PI * (1.0 - k / 16.0);
    p[k] = {200 + 90 * std::cos(a), 200 + 110 * std::sin(a) * (k > 0 && k < 16 ? 1 : 0.2)};
  }
  for (int k = 17; k <= 26; ++k) p[k] = {130.0 + (k - 17) * 15.5, 150.0};
  for (int k = 27; k <= 35; ++k)
    p[k] = {200.0 + (k >= 31 ? (k - 33) * 8.0 : 0), 170.0 + (k - 27) * 6.0};
  for (int k = 36; k <= 47; ++k) {
    const double cx = k < 42 ? 160 : 240, a = 2 * M_PI * ((k - 36) % 6) / 6.0;
    p[k] = {cx + 18 * std::cos(a), 175 + 6 * std::sin(a)};
  }
  for (int k = 48; k <= 67; ++k) {
    const double a = 2 * M_PI * (k - 48) / 20.0;
    p[k] = {200 + 35 * std::cos(a), 260 + 12 * std::sin(a)};
  }
  return p;
}

Landmarks68 similar(const Landmarks68& p, double scale, double angle, cv::Point2d shift) {
  Landmarks68 q;
  for (int k = 0; k < 68; ++k)
    q[k] = {scale * (std::cos(angle) * p[k].x - std::sin(angle) * p[k].y) + shift.x,
            scale * (std::sin(angle) * p[k].x + std::cos(angle) * p[k].y) + shift.y};
  return q;
}

TEST(ShapeNme, ZeroForTheSameShapeUnderAnySimilarity) {
  const Landmarks68 real = layout();
  EXPECT_NEAR(shape_nme(real, real), 0.0, 1e-9);
  EXPECT_NEAR(shape_nme(similar(real, 0.6, 0.3, {40, -25}), real), 0.0, 1e-4);
}

TEST(ShapeNme, IsTheMeanScoredDistanceOverTheOuterEyeDistance) {
  const Landmarks68 real = layout();
  Landmarks68 view = real;
  for (int k = 48; k <= 67; ++k) view[k].y += 10;  // mouth 10 px lower: 20 of 46 points move
  const double iod = cv::norm(real[36] - real[45]);
  EXPECT_NEAR(shape_nme(view, real), 20 * 10 / 46.0 / iod, 1e-6);
  // The eye points are not scored and only align: moving the brows changes nothing.
  for (int k = 17; k <= 26; ++k) view[k].y -= 30;
  EXPECT_NEAR(shape_nme(view, real), 20 * 10 / 46.0 / iod, 1e-6);
}

// The nose tip's place between the outer eye corners: 0.5 frontal, past 1 on a face turned
// until the nose crosses the eye at point 45, NaN when the corners share a column.
TEST(NoseBetweenEyes, PlacesTheNoseTipBetweenTheOuterEyeCorners) {
  Landmarks68 p;
  p.fill({0, 0});
  p[36] = {100, 50}, p[45] = {200, 50}, p[30] = {150, 90};
  EXPECT_DOUBLE_EQ(nose_between_eyes(p), 0.5);
  p[30].x = 230;
  EXPECT_DOUBLE_EQ(nose_between_eyes(p), 1.3);
  std::swap(p[36], p[45]);  // the corners the other way round: measured from point 36 still
  EXPECT_DOUBLE_EQ(nose_between_eyes(p), -0.3);
  p[45].x = p[36].x;
  EXPECT_TRUE(std::isnan(nose_between_eyes(p)));
}

TEST(ShapeNme, RefusesDegenerateEyesAndCountsAMissAsOne) {
  Landmarks68 real = layout();
  EXPECT_EQ(shape_nme_or_miss(std::nullopt, real), 1.0);
  Landmarks68 flat = real;
  for (int k = 36; k <= 47; ++k) flat[k] = {100, 100};
  EXPECT_THROW(shape_nme(real, flat), std::invalid_argument);
}

class Judge : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!predictor_available()) GTEST_SKIP() << "no dlib predictor (libdlib-data)";
  }
};

TEST_F(Judge, RefusesBadImagesAndAMissingModel) {
  EXPECT_THROW(FaceJudge("/nonexistent/predictor.dat"), std::runtime_error);
  const FaceJudge judge;
  EXPECT_THROW(judge.largest_face(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(judge.largest_face(cv::Mat(100, 100, CV_16UC3, cv::Scalar(0))),
               std::invalid_argument);
  EXPECT_FALSE(judge.largest_face(cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 90, 90))));
}

// The detection score: found faces score at least 0 (dlib's own threshold), a plain image the
// floor, and the same face half hidden less than whole (it stays continuous where "found" flips).
TEST_F(Judge, SearchScoresFacesContinuously) {
  const FaceJudge judge;
  EXPECT_THROW(judge.search(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(judge.search(cv::Mat(100, 100, CV_32FC1, cv::Scalar(0))), std::invalid_argument);
  const FaceSearch plain = judge.search(cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 90, 90)));
  EXPECT_FALSE(plain.face);
  EXPECT_EQ(plain.score, kNoFaceScore);
  sim::RigOptions ro;
  ro.px_per_mm = 2.4;
  render::Renderer renderer;
  const sim::Capture cap = sim::simulate_capture(sim::make_head(0), ro, renderer);
  const FaceSearch whole = judge.search(cap.front);
  ASSERT_TRUE(whole.face);
  EXPECT_GE(whole.score, 0.0);
  EXPECT_EQ(whole.face->box, judge.largest_face(cap.front)->box);
  // The face's lower half painted over with the background's colour.
  cv::Mat half = cap.front.clone();
  const cv::Rect& box = whole.face->box;
  half(cv::Rect(box.x, box.y + box.height / 2, box.width, box.height - box.height / 2) &
       cv::Rect(0, 0, half.cols, half.rows))
      .setTo(half.at<cv::Vec3b>(2, 2));
  const FaceSearch hidden = judge.search(half);
  std::printf("sim head 0 front: score %.3f whole, %.3f half hidden\n", whole.score, hidden.score);
  EXPECT_LT(hidden.score, whole.score - 0.2);
  EXPECT_GT(hidden.score, kNoFaceScore);  // a window below the threshold still counts
}

// Human-annotated 68 points (300-W's image_0010, a turned head): the judge must agree with
// people. (The other annotated photo, Einstein with his tongue out, is not found by dlib's
// detector: it returns a small false face elsewhere, so it cannot serve here.)
TEST_F(Judge, AgreesWithHumanAnnotations) {
  const std::string dir = testing::shared_data("ibug68_annotated_photos");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data/ibug68_annotated_photos";
  const FaceJudge judge;
  for (const char* name : {"image_0010"}) {
    const std::string stem = dir + "/" + name;
    const cv::Mat image = cv::imread(stem + ".png");
    ASSERT_FALSE(image.empty()) << stem;
    std::ifstream in(stem + ".pts");
    std::string line;
    while (std::getline(in, line) && line.find('{') == std::string::npos) {
    }
    Landmarks68 truth;
    for (auto& p : truth) {
      ASSERT_TRUE(in >> p.x >> p.y) << stem;
      p -= cv::Point2d(1, 1);  // 300-W points are 1-based
    }
    const auto face = judge.largest_face(image);
    ASSERT_TRUE(face) << name;
    double sum = 0;
    for (int k = 0; k < 68; ++k) sum += cv::norm(face->points[k] - truth[k]);
    const double nme = sum / 68 / cv::norm(truth[36] - truth[45]);
    std::printf("%s: dlib vs human, mean error %.3f of the outer-eye distance\n", name, nme);
    EXPECT_LT(nme, 0.1);
    EXPECT_LT(shape_nme(face->points, truth), 0.1);
  }
}

// On a simulated head: the view synthesized from the two photos onto the true mesh scores near
// 0 against the true view at the same yaw, and the unrotated front view scores clearly worse.
TEST_F(Judge, ScoresSimulatedHeadsTrueViews) {
  const sim::Head head = sim::make_head(0);
  sim::RigOptions ro;
  ro.px_per_mm = 2.4;
  render::Renderer renderer;
  const sim::Capture cap = sim::simulate_capture(head, ro, renderer);
  mesh::TriMesh bare;
  bare.vertices = head.mesh.vertices;
  bare.triangles = head.mesh.triangles;
  const double yaw = 30 * M_PI / 180;
  const render::SynthesisResult synthesized =
      render::synthesize_view(bare, cap.true_rig, cap.front, cap.side,
                              capture::camera_at(cap.nominal_rig.front, yaw, 0, 1000));
  const FaceJudge judge;
  const auto truth = judge.largest_face(sim::true_view(head, ro, yaw, 0, renderer).image);
  const auto view = judge.largest_face(synthesized.view.image);
  const auto front = judge.largest_face(cap.front);
  ASSERT_TRUE(truth);
  ASSERT_TRUE(view);
  ASSERT_TRUE(front);
  const double right = shape_nme(view->points, truth->points);
  const double unrotated = shape_nme(front->points, truth->points);
  std::printf("sim head 0 at 30 deg: synthesized on the true mesh NME %.3f, front view %.3f\n",
              right, unrotated);
  EXPECT_LT(right, 0.08);  // measured 0.059: the photos carry their own shading
  EXPECT_GT(unrotated, 2 * right);
}

}  // namespace
}  // namespace orthoface::judge
