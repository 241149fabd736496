// The side photo: the face profile, which way it faces, the eye behind it.
#include "vision/side_profile.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "vision/contour_chain.h"
#include "vision/feature_filters.h"

namespace ov = orthoface::vision;

// A left-facing profile polygon (crown, forehead, nose, lips, chin, under-chin, throat) closed
// behind by the back of the head and the neck; head height 200 px.
std::vector<cv::Point> profile_polygon() {
  return {{150, 20},  {110, 40},  {100, 90},  {102, 110}, {80, 130},  {96, 142},
          {92, 160},  {98, 175},  {94, 195},  {120, 215}, {160, 218}, {165, 300},
          {240, 300}, {245, 200}, {255, 120}, {230, 40}};
}

// The front profile of `poly` (its points above row 300 and the midpoints after them), at 1 px
// steps.
std::vector<cv::Point2d> front_curve(const std::vector<cv::Point>& poly) {
  std::vector<cv::Point2d> curve;
  for (size_t i = 0; i + 1 < poly.size() && poly[i].y < 300; ++i) {
    curve.emplace_back(poly[i]);
    curve.emplace_back((poly[i] + poly[i + 1]) / 2);
  }
  return ov::resample(curve, 1.0);
}

// The profile landmarks of `poly`'s front profile, head height 200 px.
ov::SideProfile landmarks_of(const std::vector<cv::Point>& poly) {
  ov::SideProfile sp;
  sp.curve = front_curve(poly);
  sp.head_height_px = 200;
  sp.confidence = 1.0;
  ov::find_profile_landmarks(cv::Mat(320, 320, CV_8UC3, cv::Scalar(60, 90, 140)), sp);
  return sp;
}

TEST(SideProfile, FaceProfileShapeAndFacing) {
  const auto poly = profile_polygon();
  EXPECT_TRUE(ov::reads_as_face_profile(front_curve(poly), 200));
  // The back of the head (a smooth arc down to the neck) is no face.
  std::vector<cv::Point2d> back;
  for (int i = 0; i <= 100; ++i)
    back.emplace_back(150 - 100 * std::sin(M_PI * i / 100), 20 + 2.6 * i);
  EXPECT_FALSE(ov::reads_as_face_profile(back, 200));
  // The back of a skin-only blob (dark hair before a dark background left out of it, FRMDB
  // 020): the nape runs down and forward to the neck's back, then back along a collar. It has a
  // "tip" and a backward run under it, as a face has, but no step back between the two; before
  // the step was asked for it read as a face, and with the face side reading as one too the
  // facing was left to the skin cue, which took 020's profile for one looking the other way.
  std::vector<cv::Point2d> nape;
  for (int i = 0; i <= 120; ++i) nape.emplace_back(150 - 0.75 * i, 20 + i);  // down and forward
  for (int i = 1; i <= 140; ++i) nape.emplace_back(60 + i, 140 + 0.43 * i);  // back along a collar
  EXPECT_FALSE(ov::reads_as_face_profile(ov::resample(nape, 1.0), 200));
  EXPECT_FALSE(ov::reads_as_face_profile({}, 200));               // degenerate input
  EXPECT_FALSE(ov::reads_as_face_profile(front_curve(poly), 0));  // no head height
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

// A head that leans forward (or a forehead that slopes back): the profile runs forward all the
// way from the crown to the nose tip, with no point behind the brow, but bends at the nasion
// (row 110: the forehead's slope above, the nose's below). The nasion is that bend, not the brow
// band's lowest row (row 86, which the most posterior point after the brow gave).
TEST(SideProfile, NasionIsTheBendWhenTheHeadLeansForward) {
  const std::vector<cv::Point> poly = {{150, 20}, {118, 40},  {104, 90},  {100, 110},
                                       {80, 130}, {96, 142},  {92, 160},  {98, 175},
                                       {94, 195}, {120, 215}, {160, 218}, {165, 300}};
  const ov::SideProfile sp = landmarks_of(poly);
  ASSERT_EQ(sp.features.count("nose_tip"), 1u);
  EXPECT_NEAR(sp.features.at("nose_tip").px.y, 130, 1.0);
  ASSERT_EQ(sp.features.count("nose_bridge"), 1u);
  EXPECT_NEAR(sp.features.at("nose_bridge").px.y, 110, 6.0);
  // A profile with its own dip behind the brow (the face upright) keeps the dip: row 110.
  const ov::SideProfile upright = landmarks_of(profile_polygon());
  ASSERT_EQ(upright.features.count("nose_bridge"), 1u);
  EXPECT_NEAR(upright.features.at("nose_bridge").px.y, 110, 1.5);
}

// A notch in the head's blob at the hairline (FRMDB 001: brown hair lost against a dark
// curtain): the front contour runs from the crown into a wedge that reaches 85 px back and down
// to the nasion's row, comes out again and only then runs down the forehead. The nasion was the
// wedge's far end (x 185); it is the bend on the face's own front edge (x about 102).
TEST(SideProfile, ANotchAtTheHairlineIsNotTheNasion) {
  std::vector<cv::Point> poly = profile_polygon();
  // After {110, 40}: into the wedge and out of it, then {100, 90} down the forehead.
  poly.insert(poly.begin() + 2, {{111, 44}, {180, 60}, {185, 106}, {113, 48}});
  const ov::SideProfile sp = landmarks_of(poly);
  ASSERT_EQ(sp.features.count("nose_bridge"), 1u);
  EXPECT_LT(sp.features.at("nose_bridge").px.x, 110);
  EXPECT_NEAR(sp.features.at("nose_bridge").px.y, 110, 6.0);
  EXPECT_NEAR(sp.features.at("nose_tip").px.y, 130, 1.0);
  // The profile the model is built from keeps no point of the wedge.
  for (const cv::Point2d& p : sp.curve) {
    if (p.y > 50 && p.y < 106) {
      EXPECT_LT(p.x, 120) << "row " << p.y;
    }
  }
}

// Dark hair lost against a dark background (FRMDB 028, 034): the blob, and the curve, start at
// the hairline (row 75), not the crown, so the face band 0.35..0.85 head heights below the top
// (rows 145..245) holds the lips and not the nose tip (row 130). The front photo's nose row
// finds it; a band without a point projecting past both its ends (rows not shared after all)
// falls back to the face band.
TEST(SideProfile, TheFrontsNoseRowFindsTheTipWhenTheHairIsLost) {
  const std::vector<cv::Point> poly = {{104, 75},  {100, 90},  {102, 110}, {80, 130},  {96, 142},
                                       {92, 160},  {98, 175},  {94, 195},  {120, 215}, {160, 218},
                                       {165, 300}, {240, 300}, {245, 200}, {240, 75}};
  ov::SideProfile sp = landmarks_of(poly);
  ASSERT_EQ(sp.features.count("nose_tip"), 1u);
  EXPECT_GT(sp.features.at("nose_tip").px.y, 150);  // the face band alone: on the lips
  sp = ov::SideProfile{};
  sp.curve = front_curve(poly);
  sp.head_height_px = 200;
  sp.confidence = 1.0;
  ov::find_profile_landmarks(cv::Mat(320, 320, CV_8UC3, cv::Scalar(60, 90, 140)), sp, 125);
  ASSERT_EQ(sp.features.count("nose_tip"), 1u);
  EXPECT_NEAR(sp.features.at("nose_tip").px.y, 130, 1.0);
  EXPECT_NEAR(sp.features.at("nose_bridge").px.y, 110, 6.0);
  // A row above the curve (its band holds no point of it) falls back to the face band.
  const cv::Point2d face_band_tip = landmarks_of(poly).features.at("nose_tip").px;
  sp.features.clear();
  sp.curve = front_curve(poly);
  ov::find_profile_landmarks(cv::Mat(320, 320, CV_8UC3, cv::Scalar(60, 90, 140)), sp, 40);
  EXPECT_LT(cv::norm(sp.features.at("nose_tip").px - face_band_tip), 1e-9);
  ov::SideProfileOptions o;
  o.expected_nose_row = std::nan("");
  EXPECT_THROW(o.check(), std::invalid_argument);
}

// A receding chin (FRMDB 020): below the lower lip the profile steps back a little (the
// mentolabial fold), then runs down and back along the chin to the menton (row 229), then back
// under the jaw. The chin's slope heads back 0.07 H within 0.15 H too, but down more than back;
// taken for the under-chin it put the chin and the chin bottom on the lower lip (rows 185-190).
TEST(SideProfile, ARecedingChinIsNotTheUnderChin) {
  const std::vector<cv::Point> poly = {{150, 20},  {110, 40},  {100, 90},  {102, 110}, {80, 130},
                                       {96, 142},  {92, 160},  {98, 175},  {94, 185},  {98, 186},
                                       {108, 203}, {112, 208}, {111, 214}, {116, 224}, {120, 229},
                                       {160, 232}, {165, 300}};
  const ov::SideProfile sp = landmarks_of(poly);
  ASSERT_EQ(sp.features.count("chin"), 1u);
  ASSERT_EQ(sp.features.count("chin_bottom"), 1u);
  ASSERT_EQ(sp.features.count("lip_lower"), 1u);
  EXPECT_NEAR(sp.features.at("chin").px.y, 214, 4.0);
  EXPECT_NEAR(sp.features.at("chin_bottom").px.y, 226, 8.0);  // the menton, not the lip
  EXPECT_NEAR(sp.features.at("lip_lower").px.y, 185, 6.0);
  // The upright profile keeps its chin (row 195) and its bottom above the under-chin (row 215).
  const ov::SideProfile upright = landmarks_of(profile_polygon());
  EXPECT_NEAR(upright.features.at("chin").px.y, 195, 3.0);
  EXPECT_GT(upright.features.at("chin_bottom").px.y, 195);
  EXPECT_LT(upright.features.at("chin_bottom").px.y, 216);
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
