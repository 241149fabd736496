// The live view of the conferencing station: a fitted head, tracked in every live front frame,
// re-textured from the live frames where the head really is, turned by the requested correction
// and drawn into the live frame. The one code path of `orthoface station` and its benchmark.
#pragma once

#include <memory>
#include <optional>

#include <opencv2/core.hpp>

#include "reconstruct/head_tracker.h"
#include "reconstruct/reconstruction.h"
#include "render/new_view.h"

namespace orthoface::reconstruct {

struct LiveViewOptions {
  bool tracking = true;  // false: the head is taken to stay where it was fitted
  // The side frame is a still of the fit (one camera: the enrolment's profile photo, given as
  // every update's `side`): its camera stays where the fit put it while the head moves.
  bool still_side = false;
  TrackerOptions tracker;
  // false: the tracker follows the face above the lips' line only (TrackerOptions::min_height_mm;
  // the lower lip and jaw move as the person talks); true: the whole face.
  bool track_mouth = false;
  // Within this share of the frame's width outside the drawn head the live frame's own pixels
  // stay (ViewScene::composite's keep_px): where the fitted hull falls a few pixels short of the
  // real head, its real edge shows rather than the removed region's fill, and the real scene
  // beside the head rather than an inpainted one. A head moved further than this by the
  // correction leaves no trace of its old place. 0: the removed region filled throughout.
  double keep_live_band = 0.015;
  // A live frame's pixel that differs from the scene behind the head (the fit's front photo
  // without the head) by at most this many grey levels, and joins the frame's border through
  // such pixels, is background: the model takes no colour from it. Where the fitted hull
  // reaches past the real head (the crown seen from above) it would paint the scene's colour
  // over the head's rim; the surroundings' colours fill it instead. 0: no such mask.
  int scene_difference = 8;
  // The head hull, coarser than the offline views' (2 mm, 96): each of its triangles is drawn
  // three times a frame (two source depth maps and the view).
  model::HullOptions hull = [] {
    model::HullOptions h;
    h.slice_mm = 4;
    h.angles = 64;
    return h;
  }();
};

// One output frame and what it cost.
struct LiveFrame {
  cv::Mat image;                // 8-bit BGR, the front camera's size
  capture::CameraModel camera;  // the view's camera (head frame): where the model is drawn
  TrackResult track;            // tracked = false with a reason while the head is lost
  double track_ms = 0;          // tracking (0 without)
  double texture_ms = 0;        // new source cameras and live photos
  double draw_ms = 0;           // the view and the compositing
};

class LiveView {
 public:
  // From a fit of the station's pair (reconstruct::from_photos of the same cameras). Throws
  // std::invalid_argument when the fit has no photos. When the tracker cannot start on the fit's
  // front photo (too little texture on the face), the view is drawn untracked and every frame's
  // track.reason says why.
  LiveView(const Reconstruction& fit, const LiveViewOptions& options = {});
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // A refit: new model, scene and tracker reference, the same render context.
  void refit(const Reconstruction& fit);

  // The live pair (the cameras' size, 8-bit BGR) taken at t_s seconds: the head tracked in
  // `front`, re-textured from both frames when `retexture` (else the last frames' texture),
  // turned by yaw / pitch degrees about its neck (capture::turned_camera) and composited into
  // `front`. yaw / pitch 0 gives the live frame back where the head is. Throws
  // std::invalid_argument for frames of the wrong size or type, or a non-finite yaw, pitch or
  // time.
  LiveFrame update(const cv::Mat& front, const cv::Mat& side, double t_s, double yaw_deg,
                   double pitch_deg, bool retexture = true);

  const ViewModel& model() const { return model_; }

 private:
  void load(const Reconstruction& fit);

  LiveViewOptions options_;
  capture::RigCalibration rig_, photo_rig_;
  ViewModel model_;
  ViewScene scene_;
  std::unique_ptr<render::ViewSynthesizer> synth_;
  std::unique_ptr<HeadTracker> tracker_;
  std::string tracker_error_;  // why there is no tracker
  cv::Mat scene_known_;        // CV_8U: where the scene shows background (removed, or not subject)
  cv::Mat side_scene_, side_known_;  // the fit's side photo, and where it shows background
  bool textured_ = false;            // live photos were set since the fit
  HeadPose textured_pose_;           // the pose the source cameras were last set to
};

}  // namespace orthoface::reconstruct
