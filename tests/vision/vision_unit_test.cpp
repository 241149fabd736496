// Unit tests of the vision building blocks on synthetic images with known answers.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/common/test_data.h"
#include "vision/bspline.h"
#include "vision/contour_chain.h"
#include "vision/curve_features.h"
#include "vision/edges.h"
#include "vision/feature_filters.h"
#include "vision/foreground.h"
#include "vision/front_features.h"
#include "vision/image_prep.h"
#include "vision/observation_io.h"
#include "vision/profile_fit.h"
#include "vision/side_profile.h"

namespace ov = orthoface::vision;

TEST(BSpline, FitReproducesALine) {
  std::vector<cv::Point2d> pts;
  for (int i = 0; i <= 50; ++i) pts.emplace_back(10 + 2.0 * i, 5 + 1.0 * i);
  const ov::BSpline2d s = ov::fit_bspline(pts, ov::chord_parameters(pts), {}, 8, 0.0);
  for (double t : {0.0, 0.3, 0.77, 1.0}) {
    const cv::Point2d p = ov::bspline_point(s, t);
    EXPECT_NEAR(p.x, 10 + 100 * t, 1e-3);
    EXPECT_NEAR(p.y, 5 + 50 * t, 1e-3);
  }
}

TEST(BSpline, RejectsBadInput) {
  EXPECT_THROW(ov::bspline_point(ov::BSpline2d{{{0, 0}, {1, 1}}}, 0.5), std::invalid_argument);
  EXPECT_THROW(ov::fit_bspline({{0, 0}}, {0.0}, {}, 3, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::fit_bspline({{0, 0}, {1, 1}}, {0.0}, {}, 4, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::chord_parameters({}), std::invalid_argument);
}

TEST(BSpline, DegenerateAllPointsEqual) {
  const std::vector<cv::Point2d> pts(10, cv::Point2d(3, 4));
  const auto t = ov::chord_parameters(pts);  // zero length: uniform parameters
  EXPECT_DOUBLE_EQ(t.back(), 1.0);
  const ov::BSpline2d s = ov::fit_bspline(pts, t, {}, 4, 0.1);
  EXPECT_NEAR(ov::bspline_point(s, 0.5).x, 3, 1e-6);
}

// A filled disc of radius 80 px: the profile model started 5 px off must land on its edge.
TEST(ProfileFit, ConvergesToDiscEdge) {
  cv::Mat img(300, 300, CV_32F, cv::Scalar(0));
  cv::circle(img, {150, 150}, 80, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  std::vector<cv::Point2d> init;
  for (int i = 0; i <= 40; ++i) {
    const double a = M_PI * (0.2 + 0.6 * i / 40.0);  // an arc on the disc's lower half
    init.emplace_back(150 + 85 * std::cos(a), 150 + 85 * std::sin(a));
  }
  const ov::BSpline2d s0 = ov::fit_bspline(init, ov::chord_parameters(init), {}, 10, 0.01);
  ov::ProfileFitOptions o;
  o.num_control = 10;
  const ov::ProfileFit fit = ov::fit_profile_to_edges(s0, ov::edge_image(img, {0.7, 0.1}), o);
  EXPECT_GT(fit.support, 0.95);
  const auto pts = ov::bspline_samples(fit.spline, 30);
  for (size_t i = 2; i + 2 < pts.size(); ++i)  // the clamped ends see half a search window
    EXPECT_NEAR(std::hypot(pts[i].x - 150, pts[i].y - 150), 80.0, 0.3);
}

TEST(ProfileFit, NoEdgesKeepsTheModel) {
  const cv::Mat flat(100, 100, CV_32F, cv::Scalar(0.5));
  const ov::BSpline2d s0{{{10, 10}, {30, 40}, {50, 60}, {70, 90}}};
  const ov::ProfileFit fit = ov::fit_profile_to_edges(s0, ov::edge_image(flat), {});
  EXPECT_EQ(fit.support, 0.0);
  EXPECT_NEAR(ov::bspline_point(fit.spline, 0.5).x, ov::bspline_point(s0, 0.5).x, 1.0);
  ov::ProfileFitOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(ov::fit_profile_to_edges(s0, ov::edge_image(flat), bad), std::invalid_argument);
}

TEST(EdgeImage, StepEdgeAndBadInput) {
  cv::Mat img(40, 40, CV_8U, cv::Scalar(50));
  img(cv::Rect(20, 0, 20, 40)).setTo(200);
  const ov::EdgeImage e = ov::edge_image(img);
  EXPECT_GT(e.edges.at<uchar>(20, 19) + e.edges.at<uchar>(20, 20), 0);
  EXPECT_EQ(e.edges.at<uchar>(20, 5), 0);
  EXPECT_THROW(ov::edge_image(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ov::edge_image(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  const ov::EdgeImage flat = ov::edge_image(cv::Mat(40, 40, CV_8U, cv::Scalar(7)));
  EXPECT_EQ(cv::countNonZero(flat.edges), 0);
}

TEST(SnapToColourStep, FindsThePixelBorderOfAStepAndKeepsWeakOnes) {
  cv::Mat img(30, 40, CV_8UC3, cv::Scalar(200, 200, 200));
  img(cv::Rect(20, 0, 20, 30)).setTo(cv::Scalar(90, 120, 170));  // step between columns 19 and 20
  const std::vector<cv::Point2d> pts = {{18.0, 10.0}, {21.2, 12.0}, {5.0, 15.0}};
  const std::vector<cv::Point2d> dirs(3, {1.0, 0.0});
  const auto out = ov::snap_to_colour_step(img, pts, dirs, 2.0, 20);
  EXPECT_NEAR(out[0].x, 19.5, 0.1);  // the border between the two pixel centres
  EXPECT_NEAR(out[1].x, 19.5, 0.1);
  EXPECT_DOUBLE_EQ(out[0].y, 10.0);  // moved along the direction only
  EXPECT_EQ(out[2], pts[2]);         // no step within range: unchanged
  // A diagonal direction finds the same border (the point moves along it).
  const auto diag = ov::snap_to_colour_step(img, {{18.0, 10.0}}, {{1.0, 1.0}}, 3.0, 20);
  EXPECT_NEAR(diag[0].x, 19.5, 0.1);
  EXPECT_NEAR(diag[0].y, 11.5, 0.1);
  // A step weaker than min_step leaves the point.
  EXPECT_EQ(ov::snap_to_colour_step(img, pts, dirs, 2.0, 1000)[0], pts[0]);
  EXPECT_TRUE(ov::snap_to_colour_step(img, {}, {}, 2.0, 20).empty());
  EXPECT_THROW(ov::snap_to_colour_step(cv::Mat(), pts, dirs, 2.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(cv::Mat(30, 40, CV_8U), pts, dirs, 2.0, 20),
               std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, {{1.0, 0.0}}, 2.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, dirs, 0.0, 20), std::invalid_argument);
  EXPECT_THROW(ov::snap_to_colour_step(img, pts, dirs, 2.0, -1), std::invalid_argument);
}

TEST(EdgeImage, RegionMatchesTheWholeImageInsideAndIsZeroOutside) {
  cv::Mat img(60, 80, CV_32F, cv::Scalar(0));
  cv::circle(img, {40, 30}, 15, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
  const ov::EdgeImage whole = ov::edge_image(img, {0.7, 0.1});
  const cv::Rect roi(15, 5, 50, 50);  // the disc plus 10 px
  const ov::EdgeImage part = ov::edge_image(img, {0.7, 0.1}, roi);
  ASSERT_EQ(part.gx.size(), roi.size());
  EXPECT_EQ(part.origin, roi.tl());
  EXPECT_LT(cv::norm(whole.gx(roi), part.gx, cv::NORM_INF), 1e-5);
  EXPECT_LT(cv::norm(whole.gy(roi), part.gy, cv::NORM_INF), 1e-5);
  EXPECT_NEAR(part.threshold, whole.threshold, 0.05 * whole.threshold);  // 1-in-4 sampling
  EXPECT_EQ(cv::countNonZero(part.edges != whole.edges(roi)), 0);
  // A region clipped by the image border keeps its in-image part.
  EXPECT_EQ(ov::edge_image(img, {}, cv::Rect(-5, -5, 20, 20)).gx.size(), cv::Size(15, 15));
  EXPECT_THROW(ov::edge_image(img, {}, cv::Rect(100, 100, 5, 5)), std::invalid_argument);
  EXPECT_THROW(ov::edge_image(cv::Mat(), {}, roi), std::invalid_argument);
}

// A left-facing profile polygon (crown, forehead, nose, lips, chin, under-chin, throat) closed
// behind by the back of the head and the neck; head height 200 px.
std::vector<cv::Point> profile_polygon() {
  return {{150, 20},  {110, 40},  {100, 90},  {102, 110}, {80, 130},  {96, 142},
          {92, 160},  {98, 175},  {94, 195},  {120, 215}, {160, 218}, {165, 300},
          {240, 300}, {245, 200}, {255, 120}, {230, 40}};
}

TEST(SideProfile, FaceProfileShapeAndFacing) {
  std::vector<cv::Point2d> curve;
  const auto poly = profile_polygon();
  for (size_t i = 0; i + 1 < poly.size() && poly[i].y < 300; ++i) {
    curve.emplace_back(poly[i]);
    curve.emplace_back((poly[i] + poly[i + 1]) / 2);
  }
  EXPECT_TRUE(ov::reads_as_face_profile(ov::resample(curve, 1.0), 200));
  // The back of the head (a smooth arc down to the neck) is no face.
  std::vector<cv::Point2d> back;
  for (int i = 0; i <= 100; ++i)
    back.emplace_back(150 - 100 * std::sin(M_PI * i / 100), 20 + 2.6 * i);
  EXPECT_FALSE(ov::reads_as_face_profile(back, 200));
  EXPECT_FALSE(ov::reads_as_face_profile({}, 200));                      // degenerate input
  EXPECT_FALSE(ov::reads_as_face_profile(ov::resample(curve, 1.0), 0));  // no head height
  // The facing cue on the filled blob, also mirrored.
  cv::Mat mask(320, 320, CV_8U, cv::Scalar(0));
  cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(255));
  double conf = 0;
  EXPECT_TRUE(ov::profile_faces_left(mask, &conf));
  EXPECT_GT(conf, 0.5);
  cv::Mat flipped;
  cv::flip(mask, flipped, 1);
  EXPECT_FALSE(ov::profile_faces_left(flipped, &conf));
  EXPECT_THROW(ov::profile_faces_left(mask, cv::Mat(), &conf, -1.0), std::invalid_argument);
  ov::SideProfileOptions o;
  o.min_head_height_px = -1;
  EXPECT_THROW(o.check(), std::invalid_argument);
}

// A profile facing image-left with a dark eye blob 30 px behind its edge at row 100: the eye's
// front / back ends and iris come out at the blob; plain skin or a window off the image gives none.
TEST(SideEye, FindsTheBlobBehindTheProfileAndNothingOnSkin) {
  cv::Mat img(200, 300, CV_8UC3, cv::Scalar(200, 200, 200));
  const cv::Scalar skin(90, 130, 190);  // BGR
  cv::rectangle(img, cv::Rect(100, 0, 200, 200), skin, cv::FILLED);
  const double H = 400, xp = 100;
  const ov::FilterContext plain = ov::make_filter_context(img, {150, 100}, H, {90, 40, 120, 120});
  EXPECT_FALSE(ov::find_side_eye(plain, xp, 100, H, +1).ok);
  cv::ellipse(img, cv::Point(140, 100), cv::Size(10, 4), 0, 0, 360, cv::Scalar(240, 240, 240),
              cv::FILLED);
  cv::circle(img, cv::Point(134, 100), 3, cv::Scalar(60, 30, 20), cv::FILLED);
  const ov::FilterContext c = ov::make_filter_context(img, {150, 100}, H, {90, 40, 120, 120});
  const ov::EyeFound e = ov::find_side_eye(c, xp, 100, H, +1);
  ASSERT_TRUE(e.ok);
  EXPECT_NEAR(e.corner_image_left.x, 130, 2.0);             // front end
  EXPECT_NEAR(e.corner_image_right.x, 150, 2.0);            // back end: the outer corner
  EXPECT_NEAR(e.centre.x, 134, 2.0);                        // the iris
  EXPECT_FALSE(ov::find_side_eye(c, 1000, 100, H, +1).ok);  // window off the image
  EXPECT_FALSE(ov::find_side_eye(c, xp, 100, 0, +1).ok);    // no head height
}

TEST(ContourChain, HeadWidthIgnoresTheShoulders) {
  cv::Mat mask(400, 400, CV_8U, cv::Scalar(0));
  cv::circle(mask, {200, 100}, 50, cv::Scalar(255), cv::FILLED);  // head, 101 px wide
  mask(cv::Rect(185, 140, 31, 100)).setTo(255);                   // neck
  mask(cv::Rect(40, 240, 320, 160)).setTo(255);                   // shoulders
  EXPECT_NEAR(ov::head_width(ov::row_extent(mask)), 101, 1);
  EXPECT_EQ(ov::head_width(ov::row_extent(cv::Mat(10, 10, CV_8U, cv::Scalar(0)))), 0.0);
  EXPECT_THROW(ov::row_extent(cv::Mat()), std::invalid_argument);
}

TEST(ContourChain, FrontHeadWidthStopsAtAHood) {
  // A head whose blob runs straight into a hood widening from its cheeks (no neck in between):
  // the plain walk takes the hood's width, the front-view walk stops where the widening starts.
  cv::Mat mask(500, 500, CV_8U, cv::Scalar(0));
  cv::ellipse(mask, {250, 120}, {60, 80}, 0, 0, 360, cv::Scalar(255), cv::FILLED);  // 121 px wide
  std::vector<cv::Point> hood = {{190, 130}, {310, 130}, {480, 330}, {20, 330}};
  cv::fillConvexPoly(mask, hood, cv::Scalar(255));
  mask(cv::Rect(20, 330, 461, 170)).setTo(255);
  EXPECT_GT(ov::head_width(ov::row_extent(mask)), 200);
  EXPECT_NEAR(ov::head_width(ov::row_extent(mask), true), 121, 6);
  EXPECT_EQ(ov::head_width(ov::row_extent(cv::Mat(10, 10, CV_8U, cv::Scalar(0))), true), 0.0);
}

TEST(ImagePrep, ConvertsGreySixteenBitAndAlpha) {
  cv::Mat g16(64, 64, CV_16U, cv::Scalar(1000));
  g16.at<uint16_t>(0, 0) = 4000;
  const cv::Mat a = ov::to_bgr8(g16, "test");
  EXPECT_EQ(a.type(), CV_8UC3);
  EXPECT_NEAR(a.at<cv::Vec3b>(1, 1)[0], 1000 * 255.0 / 4000, 1.0);
  EXPECT_EQ(ov::to_bgr8(cv::Mat(64, 64, CV_8UC4, cv::Scalar(1, 2, 3, 4)), "t").at<cv::Vec3b>(0, 0),
            cv::Vec3b(1, 2, 3));
  EXPECT_THROW(ov::to_bgr8(cv::Mat(), "front image"), std::invalid_argument);
  EXPECT_THROW(ov::to_bgr8(cv::Mat(1, 1, CV_8UC3), "front image"), std::invalid_argument);
  EXPECT_THROW(ov::to_bgr8(cv::Mat(40, 400, CV_8UC3), "front image"), std::invalid_argument);
}

TEST(ImagePrep, BadInputFilesGiveClearErrors) {
  const std::string dir = orthoface::testing::shared_data("bad_inputs");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data";
  for (const char* f : {"image_empty.jpg", "image_truncated.jpg", "image_text_named_jpg.jpg",
                        "image_1x1.png", "image_wide_20000x8.png", "image_huge_header.png"}) {
    try {
      ov::read_image(dir + "/" + f);
      ADD_FAILURE() << f << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(ov::read_image(dir + "/image_gray16.png").type(), CV_8UC3);
  EXPECT_EQ(ov::read_image(dir + "/image_rgba.png").type(), CV_8UC3);
  EXPECT_THROW(ov::read_image(dir + "/no_such_file.png"), std::runtime_error);
}

TEST(Segment, BorderModelFindsACentralDisc) {
  cv::Mat img(200, 200, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::circle(img, {100, 110}, 50, cv::Scalar(90, 120, 200), cv::FILLED);
  const cv::Mat m = ov::head_mask(ov::foreground_probability(img, cv::Mat()));
  ASSERT_FALSE(m.empty());
  EXPECT_NEAR(cv::countNonZero(m), M_PI * 50 * 50, 300);
  // Degenerate: a blank image has no head; a background frame of another size is refused.
  EXPECT_TRUE(ov::head_mask(ov::foreground_probability(
                                cv::Mat(200, 200, CV_8UC3, cv::Scalar(9, 9, 9)), cv::Mat()))
                  .empty());
  EXPECT_THROW(ov::foreground_probability(img, cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(ov::foreground_probability(cv::Mat(), cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ov::head_mask(cv::Mat(10, 10, CV_8U)), std::invalid_argument);
}

TEST(Segment, PixelYCrCbAndSkinMatchTheImageVersions) {
  cv::Mat img(16, 16, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  img.at<cv::Vec3b>(0, 0) = {0, 0, 0};
  img.at<cv::Vec3b>(0, 1) = {255, 255, 255};
  img.at<cv::Vec3b>(0, 2) = {90, 120, 200};  // a skin tone
  cv::Mat ycc;
  cv::cvtColor(img, ycc, cv::COLOR_BGR2YCrCb);
  const cv::Mat skin = ov::skin_probability(img);
  for (int r = 0; r < img.rows; ++r)
    for (int c = 0; c < img.cols; ++c) {
      const ov::YCrCb y = ov::to_ycrcb(img.at<cv::Vec3b>(r, c));
      const cv::Vec3b ref = ycc.at<cv::Vec3b>(r, c);
      EXPECT_NEAR(y.luma, ref[0], 1);
      EXPECT_NEAR(y.cr, ref[1], 1);
      EXPECT_NEAR(y.cb, ref[2], 1);
      EXPECT_NEAR(ov::skin_likelihood({ref[0], ref[1], ref[2]}), skin.at<float>(r, c), 1e-6);
    }
  EXPECT_GT(skin.at<float>(0, 2), 0.9f);
  EXPECT_EQ(skin.at<float>(0, 0), 0.f);  // black is no skin
  EXPECT_THROW(ov::skin_probability(cv::Mat(4, 4, CV_8U)), std::invalid_argument);
}

TEST(Segment, TwoBlobsCountedCentralOneChosen) {
  cv::Mat img(200, 300, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::circle(img, {150, 110}, 40, cv::Scalar(90, 120, 200), cv::FILLED);  // central
  cv::circle(img, {235, 110}, 35, cv::Scalar(90, 120, 200), cv::FILLED);  // off-centre
  cv::circle(img, {150, 110}, 8, cv::Scalar(200, 200, 200), cv::FILLED);  // a hole
  int blobs = 0;
  const cv::Mat m = ov::head_mask(ov::foreground_probability(img, cv::Mat()), {}, &blobs);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(blobs, 2);
  EXPECT_EQ(m.at<uchar>(110, 150), 255);  // hole filled
  EXPECT_EQ(m.at<uchar>(110, 235), 0);
  EXPECT_NEAR(cv::countNonZero(m), M_PI * 40 * 40, 250);
}

TEST(CurveFeatures, AlternatingExtremaOfASine) {
  std::vector<double> v;
  for (int i = 0; i < 400; ++i) v.push_back(std::sin(i * 2 * M_PI / 100.0));
  const auto e = ov::alternating_extrema(v, 0.5);
  ASSERT_GE(e.size(), 6u);
  EXPECT_TRUE(e[0].is_max);
  EXPECT_NEAR(e[0].index, 25, 1);
  EXPECT_NEAR(e[1].index, 75, 1);
  EXPECT_TRUE(ov::alternating_extrema(std::vector<double>(50, 1.0), 0.1).empty());
}

TEST(CentreLine, MirrorPointAcrossTiltedAxis) {
  ov::CentreLine c{100, 50, 0.0, 1};
  const cv::Point2d m = ov::mirror_point(c, {90, 10});
  EXPECT_NEAR(m.x, 110, 1e-9);
  EXPECT_NEAR(m.y, 10, 1e-9);
  c.roll_rad = 0.2;
  const cv::Point2d back = ov::mirror_point(c, ov::mirror_point(c, {37, 81}));
  EXPECT_NEAR(back.x, 37, 1e-9);
  EXPECT_NEAR(back.y, 81, 1e-9);
}

TEST(ObservationIo, RoundTripAndMalformed) {
  ov::FaceObservation o;
  o.front.width = 640;
  o.front.boundary = {{1.5, 2.5}, {3, 4}};
  o.front.features["nose_tip"] = {{320.5, 240.5}, 0.8, "profile-row", false};
  o.side.features["chin"] = {{100, 300}, 0.3, "mirrored", true};
  o.roll_rad = 0.01;
  o.side_faces_left = false;
  o.warnings = {"w1"};
  const auto dir = orthoface::testing::temp_dir("observation_io");
  ov::write_observation(o, (dir / "observation.json").string());
  const ov::FaceObservation r = ov::read_observation((dir / "observation.json").string());
  EXPECT_EQ(r.front.boundary.size(), 2u);
  EXPECT_DOUBLE_EQ(r.front.features.at("nose_tip").px.x, 320.5);
  EXPECT_TRUE(r.side.features.at("chin").mirrored);
  EXPECT_FALSE(r.side_faces_left);
  EXPECT_EQ(r.warnings, o.warnings);
  auto j = ov::to_json(o);
  j["front"]["features"]["not_a_landmark"] = j["front"]["features"]["nose_tip"];
  EXPECT_THROW(ov::observation_from_json(j), std::invalid_argument);
  j = ov::to_json(o);
  j["centre_line"].erase("roll_rad");
  EXPECT_THROW(ov::observation_from_json(j), std::invalid_argument);
  EXPECT_THROW(ov::read_observation((dir / "missing.json").string()), std::runtime_error);
  const std::string bad = orthoface::testing::shared_data("bad_inputs/json_malformed.json");
  if (!bad.empty()) {
    EXPECT_THROW(ov::read_observation(bad), std::runtime_error);
  }
}
