#include "reconstruct/live_view.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "capture/camera_model.h"
#include "model/symmetry.h"

namespace orthoface::reconstruct {
namespace {

double now_ms() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// The rig seeing the head moved by `pose` (both cameras are fixed to each other).
capture::RigCalibration posed_rig(const capture::RigCalibration& rig, const HeadPose& pose) {
  capture::RigCalibration out = rig;
  out.front = capture::posed_camera(rig.front, pose.rotation, pose.translation_mm);
  out.side = capture::posed_camera(rig.side, pose.rotation, pose.translation_mm);
  return out;
}

void check_frame(const cv::Mat& frame, const capture::CameraModel& camera, const char* which) {
  if (frame.empty() || frame.type() != CV_8UC3 || frame.cols != camera.width ||
      frame.rows != camera.height)
    throw std::invalid_argument(std::string("live view: the ") + which +
                                " frame must be 8-bit BGR of " + std::to_string(camera.width) +
                                "x" + std::to_string(camera.height));
}

// Where `frame` shows the subject: everything but the pixels within `threshold` grey levels of
// `scene` inside `known` that reach the frame's border through such pixels (so a patch of the
// head that happens to match the scene behind it stays the subject's).
cv::Mat live_subject(const cv::Mat& frame, const cv::Mat& scene, const cv::Mat& known,
                     int threshold) {
  cv::Mat diff;
  cv::absdiff(frame, scene, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  cv::Mat background = (diff <= threshold) & known;
  cv::Mat padded;  // a frame of background all round: one flood fill reaches every border pixel
  cv::copyMakeBorder(background, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(128), nullptr, cv::Scalar(), cv::Scalar(), 4);
  return padded(cv::Rect(1, 1, frame.cols, frame.rows)) != 128;
}

}  // namespace

LiveView::LiveView(const Reconstruction& fit, const LiveViewOptions& options) : options_(options) {
  options_.tracker.check();
  options_.hull.check();
  if (!(options_.keep_live_band >= 0 && options_.keep_live_band <= 0.25))
    throw std::invalid_argument("live view: keep_live_band must be within 0..0.25");
  if (options_.scene_difference < 0 || options_.scene_difference > 255)
    throw std::invalid_argument("live view: scene_difference must be within 0..255");
  load(fit);
}

LiveView::~LiveView() = default;

void LiveView::refit(const Reconstruction& fit) { load(fit); }

void LiveView::load(const Reconstruction& fit) {
  if (fit.front.empty() || fit.side.empty())
    throw std::invalid_argument("live view: the fit has no photos");
  ViewModel model = view_model(fit, HeadExtent::Whole, options_.hull);
  if (!synth_) {
    // As every view of the fit is drawn (texture from where the photos were taken, the mirror
    // plane for the side never photographed), but no side mask: the live frames move.
    synth_ = view_synthesizer(fit, model);
    synth_->set_photo_masks({}, {});
  } else {  // the same render context, reloaded as view_synthesizer loads a new one
    synth_->set_rig(fit.photo_rig);
    synth_->set_mesh(model.mesh);
    synth_->set_photos(fit.front, fit.side, cv::Mat(), cv::Mat(), render::ColourUpdate::Recompute);
    synth_->set_mirror_plane(mirror_plane(fit));
  }
  synth_->set_face_vertices(model.face_vertices);
  scene_ = view_scene(fit, *synth_);
  // The scene is background where the head was removed and wherever the fit's front photo did
  // not show the subject; elsewhere (the body below the neck) it shows the subject itself.
  scene_known_ = scene_.removed.clone();
  if (fit.front_silhouette.size() == scene_known_.size()) scene_known_ |= fit.front_silhouette == 0;
  side_scene_.release();
  side_known_.release();
  if (!options_.still_side && fit.side_silhouette.size() == fit.side.size()) {
    side_scene_ = fit.side;
    side_known_ = fit.side_silhouette == 0;
  }
  model_ = std::move(model);
  rig_ = fit.rig;
  photo_rig_ = fit.photo_rig;
  textured_ = false;
  textured_pose_ = HeadPose{};
  tracker_.reset();
  tracker_error_ = "tracking off";
  if (options_.tracking) {
    try {
      TrackerOptions to = options_.tracker;
      const auto lu = fit.landmarks.find("lip_upper"), ll = fit.landmarks.find("lip_lower");
      if (!options_.track_mouth && lu != fit.landmarks.end() && ll != fit.landmarks.end())
        to.min_height_mm = std::max(to.min_height_mm, 0.5 * (lu->second.y() + ll->second.y()));
      tracker_ = std::make_unique<HeadTracker>(model_.mesh, model_.face_vertices, photo_rig_.front,
                                               fit.front, to);
      tracker_error_.clear();
    } catch (const std::invalid_argument& e) {
      tracker_error_ = std::string("tracking off: ") + e.what();
    }
  }
}

LiveFrame LiveView::update(const cv::Mat& front, const cv::Mat& side, double t_s, double yaw_deg,
                           double pitch_deg, bool retexture) {
  check_frame(front, photo_rig_.front, "front");
  check_frame(side, photo_rig_.side, "side");
  if (!std::isfinite(t_s) || !std::isfinite(yaw_deg) || !std::isfinite(pitch_deg))
    throw std::invalid_argument("live view: time, yaw and pitch must be finite");
  LiveFrame out;
  double t = now_ms();
  if (tracker_) {
    out.track = tracker_->track(front, t_s);
  } else {
    out.track.reason = tracker_error_;
  }
  const HeadPose pose = out.track.pose;  // the fit's pose without a tracker
  out.track_ms = now_ms() - t;

  t = now_ms();
  if (retexture || !textured_) {
    // The live frames see the head where it is now: the source cameras follow it.
    // Below a tenth of a degree and a tenth of a millimetre the rig is kept (a head at rest).
    if (tracker_ && (pose.angle_to_deg(textured_pose_) > 0.1 ||
                     (pose.translation_mm - textured_pose_.translation_mm).norm() > 0.1)) {
      capture::RigCalibration rig = posed_rig(photo_rig_, pose);
      if (options_.still_side) rig.side = photo_rig_.side;
      synth_->set_rig(rig);
      textured_pose_ = pose;
    }
    if (options_.scene_difference > 0)
      synth_->set_photos(
          front, side,
          live_subject(front, scene_.background, scene_known_, options_.scene_difference),
          side_known_.empty()
              ? cv::Mat()
              : live_subject(side, side_scene_, side_known_, options_.scene_difference));
    else
      synth_->set_photos(front, side);
    textured_ = true;
  }
  out.texture_ms = now_ms() - t;

  t = now_ms();
  render::SynthesisOptions image_only;
  image_only.depth = false;  // the output shows the image; depth readback would cost a frame
  // Floating textures cost about 50 ms of CPU per 640x480 view (render_bench, case 6): too much
  // for a live frame on two cores; the offline render and batch use them.
  image_only.float_textures = false;
  // The source cameras follow the head every frame: classifying the triangles for the cheaper
  // programs (render/triangle_classes.h) would be redone each time and costs more than it saves.
  image_only.skip_unoccluded = !tracker_;
  // The head where it is, turned by the correction about its neck where it is.
  const capture::CameraModel turned =
      capture::turned_camera(rig_.front, yaw_deg, pitch_deg, pose.apply(model_.pivot));
  out.camera = capture::posed_camera(turned, pose.rotation, pose.translation_mm);
  const int keep_px = int(std::lround(options_.keep_live_band * front.cols));
  out.image = scene_.composite(synth_->render(out.camera, image_only).view, front, keep_px);
  out.draw_ms = now_ms() - t;
  return out;
}

}  // namespace orthoface::reconstruct
