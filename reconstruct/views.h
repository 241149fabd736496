// Finished new views of a reconstruction: the view synthesizer, the output framing, the unseen
// side's source and the background, set up once and drawn for any yaw / pitch. The one code path
// of `orthoface render` and of the Python module's render().
#pragma once

#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "reconstruct/reconstruction.h"
#include "render/new_view.h"

namespace orthoface::reconstruct {

// What a finished view shows behind the head.
struct ViewBackground {
  enum class Kind {
    Photo,        // the front photo's own scene with the head removed (ViewScene)
    Colour,       // `colour`
    Transparent,  // none: the image is BGRA, alpha = the view's mask (0 / 255)
  };
  Kind kind = Kind::Photo;
  cv::Scalar colour{0, 0, 0};  // BGR 0..255, for Kind::Colour
};

// A background as `orthoface render --background` names it: photo, transparent, black, white,
// grey (gray), #RRGGBB or R,G,B (0..255 each). Throws std::invalid_argument("expected ..., got
// 'TEXT'") for anything else.
ViewBackground parse_view_background(const std::string& text);

struct ViewOptions {
  HeadExtent head = HeadExtent::Whole;  // what is drawn of the subject
  int width = 0, height = 0;            // output size in pixels; 0 x 0: the front photo's
  // Blend, colour equalisation, floating textures and the unseen side's source. Its background
  // is replaced by `background.colour`.
  render::SynthesisOptions synthesis;
  ViewBackground background;
  // When synthesis.unseen needs the face's mid-plane (left / right landmark pairs) and the
  // reconstruction has none: true draws the unseen side from the front photo
  // (render::UnseenSide::Front); false refuses (std::invalid_argument).
  bool unseen_fallback = true;
  // Drawn into the photo (background photo), the neck twists into the photo's unturned body
  // (render::SynthesisOptions::body_camera); false turns the whole head and neck as one.
  bool twist_neck = true;
  void check() const;  // throws std::invalid_argument naming the bad field
};

// A finished view: `image` is 8-bit BGR (BGRA for a transparent background) of the output size;
// `view` is the synthesizer's own rendering (image on black, depth, mask).
struct FinishedView {
  cv::Mat image;
  render::RenderResult view;
};

// Built once from a reconstruction (its photos, mesh, silhouettes, landmarks), then draws any
// number of views. Views are of the front camera rescaled to the output size (render::fitted's
// framing) and turned about the head's pivot (ViewModel::camera). Owns an OSMesa context.
class ViewRenderer {
 public:
  // Throws std::invalid_argument when the options are bad, the reconstruction has no photos, or
  // (without unseen_fallback) its landmarks give no mid-plane for the unseen side.
  ViewRenderer(const Reconstruction& reconstruction, const ViewOptions& options);
  ~ViewRenderer();
  ViewRenderer(const ViewRenderer&) = delete;
  ViewRenderer& operator=(const ViewRenderer&) = delete;

  // The view at yaw / pitch in degrees (capture::camera_at's convention; `render --help`):
  // yaw -180..180, pitch -89..89, else std::invalid_argument.
  FinishedView view(double yaw_deg, double pitch_deg);
  // The camera view() draws from (the output's size, turned about the head's pivot).
  capture::CameraModel camera(double yaw_deg, double pitch_deg) const {
    return model_.camera(base_, yaw_deg, pitch_deg);
  }
  cv::Mat image(double yaw_deg, double pitch_deg) { return view(yaw_deg, pitch_deg).image; }

  int width() const { return width_; }
  int height() const { return height_; }
  // The options in force: synthesis.unseen after the fallback to the front photo.
  const ViewOptions& options() const { return options_; }

 private:
  ViewOptions options_;
  int width_ = 0, height_ = 0;
  ViewModel model_;
  std::unique_ptr<render::ViewSynthesizer> synth_;
  capture::CameraModel base_;
  ViewScene scene_;  // Kind::Photo only
};

// One view without keeping the renderer: ViewRenderer(reconstruction, options).image(yaw, pitch).
// Throws as those do.
cv::Mat view_image(const Reconstruction& reconstruction, const ViewOptions& options, double yaw_deg,
                   double pitch_deg);

}  // namespace orthoface::reconstruct
