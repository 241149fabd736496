// The subject cut out of a busy scene without clean plates (vision/scene_cut.h) and observe()'s
// use of it: sim heads in front of a room-like photograph, plain backgrounds left to the
// border-colour model.
#include "vision/scene_cut.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "sim/head.h"
#include "sim/rig.h"
#include "tests/common/scene_photo.h"
#include "tests/common/test_data.h"
#include "tests/vision/sim_eval.h"
#include "vision/foreground.h"
#include "vision/observe.h"

namespace {

namespace ov = orthoface::vision;
namespace sim = orthoface::sim;

double iou(const cv::Mat& a, const cv::Mat& b) {
  const double u = cv::countNonZero(a | b);
  return u > 0 ? cv::countNonZero(a & b) / u : 0.0;
}

bool warned(const ov::FaceObservation& obs, const std::string& what) {
  return std::any_of(obs.warnings.begin(), obs.warnings.end(),
                     [&](const std::string& w) { return w.find(what) != std::string::npos; });
}

sim::Capture in_scene(int subject) {
  sim::RigOptions ro;
  ro.seed = subject;
  ro.background = sim::BackgroundKind::Photo;
  ro.background_photo = orthoface::testing::write_scene_photo(
      (orthoface::testing::temp_dir("scene_cut_" + std::to_string(subject)) / "room.png").string(),
      subject);
  return sim::simulate_capture(sim::make_head(subject), ro);
}

// A desk photographed from above (OpenCV's sample "stuff.jpg", Debian's opencv-doc), behind sim
// subject `subject`.
const char* const kDesk = "/usr/share/doc/opencv-doc/examples/data/stuff.jpg";
sim::Capture on_desk(int subject) {
  sim::RigOptions ro;
  ro.seed = subject;
  ro.background = sim::BackgroundKind::Photo;
  ro.background_photo = kDesk;
  return sim::simulate_capture(sim::make_head(subject), ro);
}

// A head (ellipse) on a neck in a 400x300 mask, and its face box.
cv::Mat head_blob() {
  cv::Mat m = cv::Mat::zeros(300, 400, CV_8U);
  cv::ellipse(m, {200, 120}, {60, 80}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
  cv::rectangle(m, cv::Rect(170, 150, 60, 150), cv::Scalar(255), cv::FILLED);
  return m;
}
const cv::Rect2d kFace(160, 100, 80, 90);

}  // namespace

TEST(SceneCut, ABusyBorderHoldsManyColoursAPlainOneFew) {
  EXPECT_EQ(ov::border_colour_count(cv::Mat(240, 320, CV_8UC3, cv::Scalar(200, 200, 200))), 1);
  EXPECT_GT(ov::border_colour_count(orthoface::testing::scene_photo(1)),
            4 * ov::kBusyBorderColours);
  EXPECT_THROW(ov::border_colour_count(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(ov::border_colour_count(cv::Mat(10, 10, CV_8U)), std::invalid_argument);
}

TEST(SceneCut, SpillIsNoneForAHeadAndLargeWhenTheSceneJoinsIt) {
  const cv::Mat head = head_blob();
  EXPECT_EQ(ov::scene_spill(head, kFace), 0.0);
  cv::Mat joined = head.clone();
  joined.rowRange(40, 200).setTo(255);  // a wall of the scene's colours through the head's rows
  EXPECT_GT(ov::scene_spill(joined, kFace), ov::kSceneSpill);
  cv::Mat beside = cv::Mat::zeros(head.size(), CV_8U);
  cv::rectangle(beside, cv::Rect(0, 0, 100, 300), cv::Scalar(255), cv::FILLED);
  EXPECT_EQ(ov::scene_spill(beside, kFace), 1.0);     // misses the face
  EXPECT_EQ(ov::scene_spill(cv::Mat(), kFace), 1.0);  // no blob
  cv::Mat holed = head.clone();
  holed(cv::Rect(180, 100, 40, 90)).setTo(0);  // the face's colours taken for the scene
  EXPECT_EQ(ov::scene_spill(holed, kFace), 1.0);
  EXPECT_THROW(ov::scene_spill(head, cv::Rect2d()), std::invalid_argument);
  EXPECT_THROW(ov::scene_spill(cv::Mat(300, 400, CV_32F), kFace), std::invalid_argument);
}

// Before the cut, the border colours of such a room joined the scene to the head or took the
// face for the scene, and the pair failed in vision or was modelled far off.
TEST(SceneCut, ObserveCutsASimHeadOutOfABusySceneWithoutPlates) {
  const sim::Capture cap = in_scene(1);
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  EXPECT_TRUE(warned(obs, "front view: busy background")) << obs.warnings.size();
  EXPECT_GT(iou(obs.front_blob, cap.front_mask), 0.95);
  EXPECT_GT(iou(obs.side_blob, cap.side_mask), 0.95);
  const auto s = orthoface::testing::score(obs, cap);
  EXPECT_LE(s.boundary_err, 1.0);  // 0.26 px (0.28 over a plain background)
  EXPECT_LE(s.profile_err, 3.0);   // 2.2 px (0.21): GrabCut's outline, snapped to the photo's edges
  // With the cameras' clean plates the head is cut out by difference, as before.
  ov::ObserveOptions o;
  o.background_front = cap.background_front;
  o.background_side = cap.background_side;
  EXPECT_FALSE(warned(ov::observe(cap.front, cap.side, o), "busy background"));
}

// A desk photographed from above (OpenCV's sample "stuff.jpg", Debian's opencv-doc): its border
// holds few colours (11-18 of the border model's, under kBusyBorderColours), so the front blob
// comes from the border colours, and a pencil and a disc lying against the head join it; in the
// close-up scene_spill's reach lies outside the frame. The side photo's blob leaves out the
// subject's colours and is cut; the two cameras share the room, so the front is cut too. Before,
// subject 0 was modelled at 5.9 % relative error (scene_bench), 0.25 % since.
TEST(SceneCut, ASideCutOutOfTheSceneCutsTheFrontToo) {
  if (!std::filesystem::exists(kDesk)) GTEST_SKIP() << kDesk << " not installed (opencv-doc)";
  const sim::Capture cap = on_desk(0);
  ASSERT_LE(ov::border_colour_count(cap.front), ov::kBusyBorderColours);
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  EXPECT_TRUE(warned(obs, "side view: busy background"));
  EXPECT_TRUE(warned(obs, "front view: busy background (the side photo's scene is)"));
  EXPECT_GT(iou(obs.front_blob, cap.front_mask), 0.95);  // 0.959; 0.922 with the pencil and disc
  const auto s = orthoface::testing::score(obs, cap);
  EXPECT_LE(s.boundary_err, 7.0);  // 4.95 px; 14.3 px before
}

// Subject 3 before the same desk: its side blob holds the head (not cut), but a white disc lies
// against its cheek in the front photo; the front blob is then wider than the side's head is
// deep (1.25), which no head is. Before: 4.49 % relative error (scene_bench), 0.95 % since.
TEST(SceneCut, AFrontBlobWiderThanTheHeadIsDeepIsCut) {
  if (!std::filesystem::exists(kDesk)) GTEST_SKIP() << kDesk << " not installed (opencv-doc)";
  const sim::Capture cap = on_desk(3);
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  EXPECT_FALSE(warned(obs, "side view: busy background"));
  EXPECT_TRUE(warned(obs, "times as wide as the side photo's head is deep"));
  EXPECT_GT(iou(obs.front_blob, cap.front_mask), 0.93);
}

// Scene objects touching the head join GrabCut's cut when the scene's colour model lacks their
// colours: before OpenCV's cluttered table (its sample "rubberwhale1.png") a teal toy at sim
// subject 1's temple, and on the desk a dark disc on subject 3's crown. Colours the head's sure
// core never shows are dropped above the chin: the head's rows overlap the truth by 0.990 and
// 0.999, against 0.878 and 0.963 before.
TEST(SceneCut, ObjectsTouchingTheHeadInColoursItLacksAreLeftOut) {
  const char* const table = "/usr/share/doc/opencv-doc/examples/data/rubberwhale1.png";
  if (!std::filesystem::exists(table) || !std::filesystem::exists(kDesk))
    GTEST_SKIP() << "OpenCV's sample photos not installed (opencv-doc)";
  for (const auto& [subject, scene] : {std::pair{1, table}, std::pair{3, kDesk}}) {
    sim::RigOptions ro;
    ro.seed = subject;
    ro.background = sim::BackgroundKind::Photo;
    ro.background_photo = scene;
    const sim::Capture cap = sim::simulate_capture(sim::make_head(subject), ro);
    const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
    ASSERT_TRUE(warned(obs, "front view: busy background")) << scene;
    // Above the chin (the truth's landmarks: the head, not the neck the cut may widen).
    const int chin = int(cap.landmarks.at("chin_bottom").front_px.y());
    const cv::Range head(0, chin);
    const double overlap = iou(obs.front_blob.rowRange(head), cap.front_mask.rowRange(head));
    EXPECT_GT(overlap, 0.97) << "subject " << subject << " before " << scene;
  }
}

// A clean plate of one camera takes nothing away from the other photo's cut: with the front's
// plate only, the side photo of the room is still cut out around where the front's head is
// (before, the side kept its border-colour blob, and 19 of scene_bench's 25 pairs were refused
// or failed in vision); with the side's plate only, the desk the side photo shows busy still
// cuts the front (before, subject 0 was modelled at 6.0 % relative error, 0.16 % since).
TEST(SceneCut, OneCleanPlateLeavesTheOtherPhotoCutOutOfTheScene) {
  const sim::Capture room = in_scene(1);
  ov::ObserveOptions front_plate;
  front_plate.background_front = room.background_front;
  const ov::FaceObservation a = ov::observe(room.front, room.side, front_plate);
  EXPECT_TRUE(warned(a, "side view: busy background"));
  EXPECT_FALSE(warned(a, "front view: busy background"));
  EXPECT_GT(iou(a.side_blob, room.side_mask), 0.95);
  EXPECT_GT(iou(a.front_blob, room.front_mask), 0.95);

  if (!std::filesystem::exists(kDesk)) GTEST_SKIP() << kDesk << " not installed (opencv-doc)";
  const sim::Capture cap = on_desk(0);
  ov::ObserveOptions side_plate;
  side_plate.background_side = cap.background_side;
  const ov::FaceObservation b = ov::observe(cap.front, cap.side, side_plate);
  EXPECT_TRUE(warned(b, "front view: busy background (the side photo's scene is)"));
  EXPECT_FALSE(warned(b, "side view: busy background"));
  EXPECT_GT(iou(b.front_blob, cap.front_mask), 0.95);
  EXPECT_GT(iou(b.side_blob, cap.side_mask), 0.95);
}

TEST(SceneCut, AHeadIsLongerThanItIsWide) {
  const cv::Mat front = head_blob();               // 120 px wide over the face's rows
  cv::Mat side = cv::Mat::zeros(150, 300, CV_8U);  // the side photo at half the front's rows
  cv::ellipse(side, {150, 60}, {80, 40}, 0, 0, 360, cv::Scalar(255), cv::FILLED);  // 161 deep
  // Widest front row 121 px (the ellipse's 2 x 60 + 1); deepest side row 161 side px = 322
  // front px at 2 front rows per side row.
  EXPECT_NEAR(ov::head_width_to_depth(front, side, kFace, 2.0), 121.0 / 322.0, 1e-9);
  EXPECT_LT(ov::head_width_to_depth(front, side, kFace, 2.0), ov::kSceneWidthToDepth);
  cv::Mat joined = front.clone();  // a disc on the desk beside the cheek
  cv::circle(joined, {275, 150}, 25, cv::Scalar(255), cv::FILLED);
  const cv::Mat shallow = side(cv::Rect(0, 0, 300, 150)).clone();
  cv::Mat narrow = cv::Mat::zeros(150, 300, CV_8U);
  cv::ellipse(narrow, {150, 60}, {30, 40}, 0, 0, 360, cv::Scalar(255), cv::FILLED);  // 61 deep
  EXPECT_GT(ov::head_width_to_depth(joined, narrow, kFace, 2.0), ov::kSceneWidthToDepth);
  EXPECT_EQ(ov::head_width_to_depth(front, cv::Mat(), kFace, 2.0), 0.0);
  EXPECT_EQ(ov::head_width_to_depth(cv::Mat::zeros(300, 400, CV_8U), shallow, kFace, 2.0), 0.0);
  EXPECT_THROW(ov::head_width_to_depth(front, side, cv::Rect2d(), 2.0), std::invalid_argument);
  EXPECT_THROW(ov::head_width_to_depth(cv::Mat(300, 400, CV_32F), side, kFace, 2.0),
               std::invalid_argument);
  EXPECT_THROW(ov::head_width_to_depth(front, side, kFace, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::head_width_to_depth(front, side, kFace, std::nan("")), std::invalid_argument);
}

TEST(SceneCut, APlainBackgroundIsLeftToTheBorderColours) {
  const sim::Capture cap = sim::simulate_capture(sim::make_head(1), sim::RigOptions{});
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  EXPECT_FALSE(warned(obs, "busy background"));
  EXPECT_GT(iou(obs.front_blob, cap.front_mask), 0.97);
  const auto s = orthoface::testing::score(obs, cap);
  EXPECT_LE(s.boundary_err, 1.0);  // 0.28 px
  EXPECT_LE(s.profile_err, 1.0);   // 0.21 px
}

TEST(SceneCut, TheSideIsFoundWhereTheSubjectsColoursGather) {
  const sim::Capture cap = in_scene(3);
  const ov::FaceObservation obs = ov::observe(cap.front, cap.side);
  ASSERT_FALSE(obs.front_blob.empty());
  const cv::Rect2d face(cap.landmarks.at("eye_right_outer").front_px.x(),
                        cap.landmarks.at("eye_right_outer").front_px.y() - 20,
                        cap.landmarks.at("eye_left_outer").front_px.x() -
                            cap.landmarks.at("eye_right_outer").front_px.x(),
                        cap.landmarks.at("chin_bottom").front_px.y() -
                            cap.landmarks.at("eye_right_outer").front_px.y() + 20);
  const ov::SideHint hint = ov::side_hint(cap.front, cap.front_mask, face, 1.0);
  EXPECT_NEAR(hint.top, cv::boundingRect(cap.front_mask).y, 2.0);
  EXPECT_NEAR(cv::sum(hint.colours)[0], 1.0, 1e-4);
  // The true side blob leaves out little of the subject's colours, an empty one all of them.
  EXPECT_LT(ov::side_missed(cap.side, cap.side_mask, hint), ov::kSideMissed);
  EXPECT_EQ(ov::side_missed(cap.side, cv::Mat(), hint), 1.0);
  const ov::SceneCut cut = ov::cut_side(cap.side, hint);
  EXPECT_GT(iou(cut.mask, cap.side_mask), 0.93);
  EXPECT_EQ(cut.probability.type(), CV_32F);
}

TEST(SceneCut, BadInputsAreRefusedByName) {
  const cv::Mat photo = orthoface::testing::scene_photo(2, {400, 300});
  EXPECT_THROW(ov::cut_front(cv::Mat(), kFace), std::invalid_argument);
  EXPECT_THROW(ov::cut_front(cv::Mat(300, 400, CV_8U), kFace), std::invalid_argument);
  EXPECT_THROW(ov::cut_front(photo, cv::Rect2d()), std::invalid_argument);
  EXPECT_THROW(ov::cut_front(photo, cv::Rect2d(900, 900, 50, 50)), std::invalid_argument);
  EXPECT_THROW(ov::cut_front(photo, kFace, cv::Mat(10, 10, CV_32F)), std::invalid_argument);
  EXPECT_THROW(ov::side_hint(photo, cv::Mat(), kFace, 1.0), std::invalid_argument);
  EXPECT_THROW(ov::side_hint(photo, head_blob(), kFace, 0.0), std::invalid_argument);
  EXPECT_THROW(ov::side_hint(photo, cv::Mat::zeros(300, 400, CV_8U), kFace, 1.0),
               std::invalid_argument);  // does not reach the eyes
  const ov::SideHint hint = ov::side_hint(photo, head_blob(), kFace, 1.0);
  EXPECT_THROW(ov::cut_side(cv::Mat(), hint), std::invalid_argument);
  EXPECT_THROW(ov::cut_side(photo, ov::SideHint{}), std::invalid_argument);
  EXPECT_THROW(ov::side_missed(photo, cv::Mat(10, 10, CV_8U), hint), std::invalid_argument);
  EXPECT_THROW(ov::side_missed(photo, head_blob(), ov::SideHint{}), std::invalid_argument);
  try {
    ov::cut_side(photo, ov::SideHint{});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cut_side"), std::string::npos);
  }
}
