// Head tracking (reconstruct/head_tracker.h): the One-Euro filter, and the pose of a sim head
// that turns and nods in front of the camera against its true pose; the live view built on it
// (reconstruct/live_view.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "reconstruct/head_tracker.h"
#include "reconstruct/live_view.h"
#include "reconstruct/reconstruction.h"
#include "render/image_metrics.h"
#include "render/new_view.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::reconstruct {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(OneEuroFilter, HoldsAConstantAndFollowsAStep) {
  OneEuroFilter f(1.0, 0.0);
  for (int k = 0; k < 30; ++k) EXPECT_DOUBLE_EQ(f.filter(5.0, k / 30.0), 5.0);
  // A step to 10 at 30 Hz with a 1 Hz cutoff: about 17 % of the way after one frame, most of it
  // after a second.
  const double first = f.filter(10.0, 1.0);
  EXPECT_GT(first, 5.5);
  EXPECT_LT(first, 6.5);
  double last = first;
  for (int k = 31; k <= 60; ++k) last = f.filter(10.0, k / 30.0);
  EXPECT_GT(last, 9.9);
}

TEST(OneEuroFilter, SmoothsNoiseAndLagsLittleWhenFast) {
  // Noise of +-1 at rest is cut to a fraction; a fast ramp with beta > 0 lags less than without.
  OneEuroFilter rest(1.0, 0.0);
  double worst = 0;
  for (int k = 0; k < 300; ++k) {
    const double v = rest.filter((k % 2) ? 1.0 : -1.0, k / 30.0);
    if (k > 30) worst = std::max(worst, std::abs(v));
  }
  EXPECT_LT(worst, 0.2);
  OneEuroFilter slow(1.0, 0.0), quick(1.0, 0.5);
  double lag_slow = 0, lag_quick = 0;
  for (int k = 0; k < 60; ++k) {
    const double v = 2.0 * k;  // 60 units per second
    lag_slow = v - slow.filter(v, k / 30.0);
    lag_quick = v - quick.filter(v, k / 30.0);
  }
  EXPECT_LT(lag_quick, 0.5 * lag_slow);
}

TEST(OneEuroFilter, RefusesBadSettingsAndSamples) {
  EXPECT_THROW(OneEuroFilter(0.0, 0.1), std::invalid_argument);
  EXPECT_THROW(OneEuroFilter(1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(OneEuroFilter(1.0, 0.1, NAN), std::invalid_argument);
  OneEuroFilter f;
  EXPECT_THROW(f.filter(NAN, 0.0), std::invalid_argument);
  EXPECT_THROW(f.filter(1.0, INFINITY), std::invalid_argument);
}

TEST(HeadPose, AnglesFollowTheHeadFrame) {
  HeadPose p;
  p.rotation = Eigen::AngleAxisd(20 * kPi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_NEAR(p.yaw_deg(), 20, 1e-9);
  EXPECT_NEAR(p.pitch_deg(), 0, 1e-9);
  p.rotation = Eigen::AngleAxisd(-10 * kPi / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(p.pitch_deg(), 10, 1e-9);  // the face's +z tilts toward +y: the chin lifts
  EXPECT_NEAR(p.angle_to_deg(HeadPose{}), 10, 1e-9);
  p.rotation = Eigen::AngleAxisd(7 * kPi / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(p.roll_deg(), 7, 1e-9);
}

// Sim subject 4 fitted from its rest pair, then frames of the head turned by (yaw, pitch): the
// front camera turned the other way about the head origin, as the sim camera plays it.
class HeadTracking : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    head_ = new sim::Head(sim::make_head(4));
    const sim::Capture rest = sim::simulate_capture(*head_, sim::RigOptions{});
    ReconstructOptions o;
    o.rig = rest.nominal_rig;
    rec_ = new Reconstruction(from_photos(rest.front, rest.side, o));
    model_ = new ViewModel(view_model(*rec_, HeadExtent::Whole));
    renderer_ = new render::Renderer();
  }
  static void TearDownTestSuite() {
    delete renderer_;
    delete model_;
    delete rec_;
    delete head_;
  }
  // The front frame of the head turned by yaw / pitch (degrees) and its true pose.
  static cv::Mat frame(double yaw, double pitch, HeadPose& truth) {
    sim::RigOptions o;
    o.front_error.yaw_deg = yaw;
    o.front_error.pitch_deg = pitch;
    const sim::Capture c = sim::simulate_capture(*head_, o, *renderer_);
    const Eigen::Matrix3d rn = c.nominal_rig.front.cam_from_head.linear();
    const Eigen::Matrix3d rt = c.true_rig.front.cam_from_head.linear();
    truth.rotation = rn.transpose() * rt;
    truth.translation_mm = rn.transpose() * (c.true_rig.front.cam_from_head.translation() -
                                             c.nominal_rig.front.cam_from_head.translation());
    return c.front;
  }
  static sim::Head* head_;
  static Reconstruction* rec_;
  static ViewModel* model_;
  static render::Renderer* renderer_;
};
sim::Head* HeadTracking::head_ = nullptr;
Reconstruction* HeadTracking::rec_ = nullptr;
ViewModel* HeadTracking::model_ = nullptr;
render::Renderer* HeadTracking::renderer_ = nullptr;

TEST_F(HeadTracking, FollowsATurnAndANodWithinTwoDegrees) {
  HeadTracker tracker(model_->mesh, model_->face_vertices, rec_->rig.front, rec_->front);
  EXPECT_GE(tracker.model_points(), 100);
  std::vector<double> errors;
  double worst = 0;
  // 0 -> 24 deg yaw with a nod of up to 12 deg and back, a step of 1.5 deg a frame (45 deg/s).
  for (int k = 0; k <= 32; ++k) {
    const double yaw = 24 * std::sin(kPi * k / 32), pitch = 12 * std::sin(2 * kPi * k / 32);
    HeadPose truth;
    const cv::Mat f = frame(yaw, pitch, truth);
    const TrackResult r = tracker.track(f, k / 30.0);
    ASSERT_TRUE(r.tracked) << "frame " << k << ": " << r.reason;
    const double e = r.raw.angle_to_deg(truth);
    errors.push_back(e);
    worst = std::max(worst, e);
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double median = errors[errors.size() / 2];
  RecordProperty("median_pose_error_deg", std::to_string(median));
  EXPECT_LE(median, 2.0);
  EXPECT_LE(worst, 5.0);
}

// A talking head (the jaw opening up to 10 mm while it turns and nods): the points below the
// lips move with the jaw, not with the head; tracked above them (as LiveView does) the pose
// stays within the still head's limits (here the whole face's median error is about the same:
// 1.07 against 1.04 deg).
TEST_F(HeadTracking, FollowsATalkingHeadFromAboveTheLips) {
  const double stomion =
      0.5 * (rec_->landmarks.at("lip_upper").y() + rec_->landmarks.at("lip_lower").y());
  TrackerOptions above;
  above.min_height_mm = stomion;
  HeadTracker upper(model_->mesh, model_->face_vertices, rec_->rig.front, rec_->front, above);
  HeadTracker whole(model_->mesh, model_->face_vertices, rec_->rig.front, rec_->front);
  EXPECT_LT(upper.model_points(), whole.model_points());
  EXPECT_GE(upper.model_points(), 60);
  std::vector<double> e_upper, e_whole;
  for (int k = 0; k <= 32; ++k) {
    const double yaw = 20 * std::sin(kPi * k / 32), pitch = 8 * std::sin(2 * kPi * k / 32);
    sim::RigOptions o;
    o.front_error.yaw_deg = yaw;
    o.front_error.pitch_deg = pitch;
    const double mouth = 5 * (1 - std::cos(2 * kPi * k / 8));  // 0..10 mm, 4 times
    const sim::Capture c = sim::simulate_capture(sim::open_mouth(*head_, mouth), o, *renderer_);
    HeadPose truth;
    truth.rotation = c.nominal_rig.front.cam_from_head.linear().transpose() *
                     c.true_rig.front.cam_from_head.linear();
    const TrackResult a = upper.track(c.front, k / 30.0), b = whole.track(c.front, k / 30.0);
    ASSERT_TRUE(a.tracked) << "frame " << k << ": " << a.reason;
    e_upper.push_back(a.raw.angle_to_deg(truth));
    if (b.tracked) e_whole.push_back(b.raw.angle_to_deg(truth));
  }
  std::sort(e_upper.begin(), e_upper.end());
  std::sort(e_whole.begin(), e_whole.end());
  RecordProperty("median_pose_error_deg_above_lips", std::to_string(e_upper[e_upper.size() / 2]));
  RecordProperty("median_pose_error_deg_whole_face", std::to_string(e_whole[e_whole.size() / 2]));
  EXPECT_LE(e_upper[e_upper.size() / 2], 2.0);
  EXPECT_LE(e_upper.back(), 5.0);
  TrackerOptions bad;
  bad.min_height_mm = NAN;
  EXPECT_THROW(HeadTracker(model_->mesh, 0, rec_->rig.front, rec_->front, bad),
               std::invalid_argument);
  bad.min_height_mm = 1e6;  // nothing above it: nothing to track
  EXPECT_THROW(HeadTracker(model_->mesh, 0, rec_->rig.front, rec_->front, bad),
               std::invalid_argument);
}

TEST(HeadTrackingPerspective, FollowsATurnThroughAPinholeCamera) {
  // The perspective sim rig (a 1600 px focal length at 1 m): the same solve through
  // capture::project's pinhole model.
  const sim::Head head = sim::make_head(2);
  sim::RigOptions rest;
  rest.kind = sim::RigKind::Perspective;
  render::Renderer renderer;
  const sim::Capture c0 = sim::simulate_capture(head, rest, renderer);
  ReconstructOptions o;
  o.rig = c0.nominal_rig;
  const Reconstruction rec = from_photos(c0.front, c0.side, o);
  const ViewModel model = view_model(rec, HeadExtent::Whole);
  HeadTracker tracker(model.mesh, model.face_vertices, rec.photo_rig.front, rec.front);
  std::vector<double> errors;
  for (int k = 0; k <= 16; ++k) {
    sim::RigOptions turned = rest;
    turned.front_error.yaw_deg = 20 * std::sin(kPi * k / 16);
    turned.front_error.pitch_deg = 8 * std::sin(2 * kPi * k / 16);
    const sim::Capture c = sim::simulate_capture(head, turned, renderer);
    HeadPose truth;
    const Eigen::Matrix3d rn = c.nominal_rig.front.cam_from_head.linear();
    truth.rotation = rn.transpose() * c.true_rig.front.cam_from_head.linear();
    const TrackResult r = tracker.track(c.front, k / 30.0);
    ASSERT_TRUE(r.tracked) << "frame " << k << ": " << r.reason;
    errors.push_back(r.raw.angle_to_deg(truth));
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LE(errors[errors.size() / 2], 2.0);
  EXPECT_LE(errors.back(), 5.0);
}

TEST_F(HeadTracking, SaysWhenLostAndRecovers) {
  HeadTracker tracker(model_->mesh, model_->face_vertices, rec_->rig.front, rec_->front);
  HeadPose truth;
  ASSERT_TRUE(tracker.track(frame(8, 0, truth), 0.0).tracked);
  const cv::Mat empty(rec_->front.size(), CV_8UC3, cv::Scalar(200, 200, 200));
  const TrackResult lost = tracker.track(empty, 1 / 30.0);
  EXPECT_FALSE(lost.tracked);
  EXPECT_FALSE(lost.reason.empty());
  EXPECT_TRUE(tracker.lost());
  EXPECT_NEAR(lost.pose.yaw_deg(), tracker.pose().yaw_deg(), 1e-12);  // the last good pose kept
  const TrackResult back = tracker.track(frame(4, 0, truth), 2 / 30.0);
  ASSERT_TRUE(back.tracked) << back.reason;
  EXPECT_LE(back.raw.angle_to_deg(truth), 2.0);
  EXPECT_FALSE(tracker.lost());
}

TEST_F(HeadTracking, IsSteadyAtRest) {
  // The same frame again and again: the pose stays put (no drift from frame-to-frame flow).
  HeadTracker tracker(model_->mesh, model_->face_vertices, rec_->rig.front, rec_->front);
  HeadPose truth;
  const cv::Mat f = frame(10, 5, truth);
  TrackResult first = tracker.track(f, 0.0), r;
  for (int k = 1; k < 20; ++k) r = tracker.track(f, k / 30.0);
  ASSERT_TRUE(r.tracked) << r.reason;
  EXPECT_LE(r.pose.angle_to_deg(first.pose), 0.2);
  EXPECT_LE(r.raw.angle_to_deg(truth), 2.0);
}

TEST_F(HeadTracking, RefusesBadInputs) {
  const auto& m = model_->mesh;
  const auto& cam = rec_->rig.front;
  EXPECT_THROW(HeadTracker(mesh::TriMesh{}, 0, cam, rec_->front), std::invalid_argument);
  EXPECT_THROW(HeadTracker(m, -1, cam, rec_->front), std::invalid_argument);
  EXPECT_THROW(HeadTracker(m, static_cast<int>(m.vertices.size()) + 1, cam, rec_->front),
               std::invalid_argument);
  EXPECT_THROW(HeadTracker(m, 0, cam, cv::Mat()), std::invalid_argument);
  cv::Mat small;
  cv::resize(rec_->front, small, {320, 240});
  EXPECT_THROW(HeadTracker(m, 0, cam, small), std::invalid_argument);
  cv::Mat wide;
  rec_->front.convertTo(wide, CV_32FC3);
  EXPECT_THROW(HeadTracker(m, 0, cam, wide), std::invalid_argument);
  capture::CameraModel bad = cam;
  bad.fx = NAN;
  EXPECT_THROW(HeadTracker(m, 0, bad, rec_->front), std::invalid_argument);
  TrackerOptions o;
  o.max_points = 2;
  EXPECT_THROW(HeadTracker(m, 0, cam, rec_->front, o), std::invalid_argument);
  const cv::Mat blank(rec_->front.size(), CV_8UC3, cv::Scalar(128, 128, 128));
  EXPECT_THROW(HeadTracker(m, 0, cam, blank), std::invalid_argument);  // nothing to track

  HeadTracker tracker(m, model_->face_vertices, cam, rec_->front);
  EXPECT_THROW(tracker.track(small, 0.0), std::invalid_argument);
  EXPECT_THROW(tracker.track(cv::Mat(), 0.0), std::invalid_argument);
  EXPECT_THROW(tracker.track(rec_->front, NAN), std::invalid_argument);
}

// The live view: with no correction it gives the live frame back where the head is, whether the
// head is where it was fitted or has turned (the texture follows the tracked head).
TEST_F(HeadTracking, LiveViewWithoutCorrectionGivesTheLiveFrameBack) {
  LiveView live(*rec_);
  HeadPose truth;
  for (const auto& [yaw, pitch] : {std::pair{0.0, 0.0}, {6.0, 3.0}, {12.0, 6.0}}) {
    sim::RigOptions o;
    o.front_error.yaw_deg = o.side_error.yaw_deg = yaw;
    o.front_error.pitch_deg = pitch;
    o.side_error.roll_deg = -pitch;
    const sim::Capture c = sim::simulate_capture(*head_, o, *renderer_);
    const LiveFrame f = live.update(c.front, c.side, yaw / 30.0, 0, 0);
    ASSERT_TRUE(f.track.tracked) << f.track.reason;
    // Inside the head, away from its outline (the hull's edge is not the true head's).
    cv::Mat inner;
    cv::erode(c.front_mask, inner, cv::Mat(), {-1, -1}, 6);
    const double psnr = render::psnr(c.front, f.image, inner);
    EXPECT_GE(psnr, 30.0) << "yaw " << yaw << " pitch " << pitch;
    EXPECT_EQ(f.image.size(), c.front.size());
  }
  // A correction turns the head: the output is no longer the live frame.
  const sim::Capture rest = sim::simulate_capture(*head_, sim::RigOptions{}, *renderer_);
  const LiveFrame turned = live.update(rest.front, rest.side, 1.0, 0, 10);
  EXPECT_LT(render::psnr(rest.front, turned.image, rest.front_mask), 25.0);
}

// A corrected head keeps the real head's outline: the live frame stays in a narrow band beside
// the drawn head (where the fitted hull stops short of the real head) and the model takes no
// colour from the scene behind the head (where the hull reaches past it, the crown seen from
// above). Both against the true corrected frame, over the true head.
TEST_F(HeadTracking, LiveViewCorrectedHeadKeepsTheRealOutline) {
  const sim::Capture rest = sim::simulate_capture(*head_, sim::RigOptions{}, *renderer_);
  const capture::CameraModel turned = capture::turned_camera(rec_->rig.front, 0, 10, model_->pivot);
  const render::RenderResult truth =
      sim::render_head(*head_, sim::RigOptions{}, turned, *renderer_);
  auto psnr_with = [&](double band, int difference) {
    LiveViewOptions o;
    o.keep_live_band = band;
    o.scene_difference = difference;
    LiveView live(*rec_, o);
    const LiveFrame f = live.update(rest.front, rest.side, 0.0, 0, 10);
    EXPECT_TRUE(f.track.tracked) << f.track.reason;
    return render::psnr(truth.image, f.image, truth.mask);
  };
  const double plain = psnr_with(0, 0), band = psnr_with(0.01, 0), both = psnr_with(0.01, 8);
  std::printf("pitch 10 over the true head: %.1f dB, with the band %.1f dB, and the mask %.1f dB\n",
              plain, band, both);
  EXPECT_GT(band, plain + 1.0);
  EXPECT_GT(both, band + 1.0);
}

// Turned toward the side the side camera never saw, the live view draws what every view of the
// fit draws there (view_synthesizer: the mirror view through the landmarks' mid-sagittal plane),
// not the front photo stretched over that side.
TEST_F(HeadTracking, LiveViewTurnedToTheUnseenSideIsTheFitsMirrorView) {
  LiveView live(*rec_);
  const auto synth = view_synthesizer(*rec_, live.model());
  ASSERT_TRUE(synth->mirror_plane());
  render::SynthesisOptions o;
  o.float_textures = false;
  o.depth = false;
  const sim::Capture rest = sim::simulate_capture(*head_, sim::RigOptions{}, *renderer_);
  int mirrored = 0;
  for (const double yaw : {-30.0, 30.0}) {
    const capture::CameraModel camera = live.model().camera(rec_->rig.front, yaw, 0);
    if (!synth->mirrors_view(camera, o)) continue;
    ++mirrored;
    const LiveFrame f = live.update(rest.front, rest.side, 0.0, yaw, 0);
    ASSERT_TRUE(f.track.tracked) << f.track.reason;
    const render::RenderResult want = synth->render(camera, o).view;
    // Inside the view's head, away from its outline and from the neck's fade into the frame.
    cv::Mat inner;
    cv::erode(want.mask, inner, cv::Mat(), {-1, -1}, 6);
    inner.rowRange(inner.rows * 2 / 3, inner.rows).setTo(0);
    EXPECT_GE(render::psnr(want.image, f.image, inner), 30.0) << "yaw " << yaw;
  }
  EXPECT_EQ(mirrored, 1);
}

TEST_F(HeadTracking, LiveViewUntrackedSaysSoAndRefusesBadFrames) {
  LiveViewOptions o;
  o.tracking = false;
  LiveView live(*rec_, o);
  const LiveFrame f = live.update(rec_->front, rec_->side, 0.0, 5, 0);
  EXPECT_FALSE(f.track.tracked);
  EXPECT_EQ(f.track.reason, "tracking off");
  cv::Mat small;
  cv::resize(rec_->front, small, {320, 240});
  EXPECT_THROW(live.update(small, rec_->side, 0.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(live.update(rec_->front, cv::Mat(), 0.0, 0, 0), std::invalid_argument);
  cv::Mat grey;
  cv::cvtColor(rec_->front, grey, cv::COLOR_BGR2GRAY);
  EXPECT_THROW(live.update(grey, rec_->side, 0.0, 0, 0), std::invalid_argument);
  EXPECT_THROW(live.update(rec_->front, rec_->side, NAN, 0, 0), std::invalid_argument);
  EXPECT_THROW(live.update(rec_->front, rec_->side, 0.0, INFINITY, 0), std::invalid_argument);
  Reconstruction no_photos = *rec_;
  no_photos.front = cv::Mat();
  EXPECT_THROW(LiveView{no_photos}, std::invalid_argument);
  o.tracker.min_inliers = 1;
  EXPECT_THROW(LiveView(*rec_, o), std::invalid_argument);
  o = LiveViewOptions{};
  o.keep_live_band = -0.01;
  EXPECT_THROW(LiveView(*rec_, o), std::invalid_argument);
  o.keep_live_band = NAN;
  EXPECT_THROW(LiveView(*rec_, o), std::invalid_argument);
  o = LiveViewOptions{};
  o.scene_difference = -1;
  EXPECT_THROW(LiveView(*rec_, o), std::invalid_argument);
  o.scene_difference = 256;
  EXPECT_THROW(LiveView(*rec_, o), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::reconstruct
