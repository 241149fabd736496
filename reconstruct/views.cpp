// Finished new views of a reconstruction (`orthoface render`, the Python module's render()).
#include "reconstruct/views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/renderer.h"

namespace orthoface::reconstruct {
namespace {

// The front camera rescaled to the output size (the framing of render::fitted).
capture::CameraModel scaled_front(const capture::RigCalibration& rig, int width, int height) {
  const capture::CameraModel& front = rig.front;
  capture::CameraModel k = front;
  const double sx = double(width) / front.width, sy = double(height) / front.height;
  const double s = std::min(sx, sy);
  k.width = width;
  k.height = height;
  k.fx = front.fx * s;
  k.fy = front.fy * s;
  k.cx = width / 2.0 + (front.cx - front.width / 2.0) * s;
  k.cy = height / 2.0 + (front.cy - front.height / 2.0) * s;
  return k;
}

// The view as BGRA with its mask as alpha.
cv::Mat with_alpha(const render::RenderResult& r) {
  cv::Mat bgra;
  cv::cvtColor(r.image, bgra, cv::COLOR_BGR2BGRA);
  cv::Mat channels[4];
  cv::split(bgra, channels);
  channels[3] = r.mask.clone();
  cv::merge(channels, 4, bgra);
  return bgra;
}

std::string degrees(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

}  // namespace

ViewBackground parse_view_background(const std::string& text) {
  ViewBackground b;
  if (text == "photo") return b;
  if (text == "transparent") {
    b.kind = ViewBackground::Kind::Transparent;
    return b;
  }
  b.kind = ViewBackground::Kind::Colour;
  if (text == "black") return b;
  if (text == "white") return b.colour = {255, 255, 255}, b;
  if (text == "grey" || text == "gray") return b.colour = {128, 128, 128}, b;
  int r = 0, g = 0, bl = 0;
  char tail = 0;
  if (text.size() == 7 && text[0] == '#' &&
      std::sscanf(text.c_str() + 1, "%2x%2x%2x%c", &r, &g, &bl, &tail) == 3)
    return b.colour = {double(bl), double(g), double(r)}, b;
  if (std::sscanf(text.c_str(), "%d,%d,%d%c", &r, &g, &bl, &tail) == 3 && r >= 0 && r <= 255 &&
      g >= 0 && g <= 255 && bl >= 0 && bl <= 255)
    return b.colour = {double(bl), double(g), double(r)}, b;
  throw std::invalid_argument(
      "expected photo, black, white, grey, #RRGGBB, R,G,B or transparent, got '" + text + "'");
}

void ViewOptions::check() const {
  const bool source_size = width == 0 && height == 0;
  if (!source_size && (width < 1 || height < 1 || width > render::kMaxRenderSize ||
                       height > render::kMaxRenderSize))
    throw std::invalid_argument("view size " + std::to_string(width) + "x" +
                                std::to_string(height) + ": each side must be 1.." +
                                std::to_string(render::kMaxRenderSize) +
                                " (0x0: the front photo's size)");
  for (int i = 0; i < 3; ++i)
    if (!(background.colour[i] >= 0 && background.colour[i] <= 255))
      throw std::invalid_argument("view background colour: each channel must be 0..255");
  synthesis.check();
}

ViewRenderer::ViewRenderer(const Reconstruction& r, const ViewOptions& options)
    : options_(options) {
  options_.check();
  if (r.front.empty() || r.side.empty())
    throw std::invalid_argument("views: the reconstruction has no photos");
  width_ = options_.width ? options_.width : r.front.cols;
  height_ = options_.height ? options_.height : r.front.rows;
  if (options_.background.kind == ViewBackground::Kind::Colour)
    options_.synthesis.background = options_.background.colour;
  model_ = view_model(r, options_.head);
  synth_ = view_synthesizer(r, model_);
  base_ = scaled_front(r.photo_rig, width_, height_);
  if (options_.synthesis.unseen != render::UnseenSide::Front && !synth_->mirror_plane()) {
    if (!options_.unseen_fallback)
      throw std::invalid_argument(std::string("unseen side ") +
                                  render::unseen_side_name(options_.synthesis.unseen) +
                                  ": the reconstruction has no landmarks with left / right "
                                  "feature pairs");
    options_.synthesis.unseen = render::UnseenSide::Front;
  }
  if (options_.background.kind == ViewBackground::Kind::Photo) {
    scene_ = view_scene(r, *synth_, options_.twist_neck).fitted(width_, height_);
    // Drawn into the photo, the body stays as the photo shows it: the neck twists into it.
    if (options_.twist_neck) {
      options_.synthesis.body_camera = base_;
      options_.synthesis.body_pivot = model_.pivot;
    }
  }
}

ViewRenderer::~ViewRenderer() = default;

FinishedView ViewRenderer::view(double yaw_deg, double pitch_deg) {
  if (!(yaw_deg >= -180 && yaw_deg <= 180))
    throw std::invalid_argument("yaw " + degrees(yaw_deg) + ": expected -180..180 degrees");
  if (!(pitch_deg >= -89 && pitch_deg <= 89))
    throw std::invalid_argument("pitch " + degrees(pitch_deg) + ": expected -89..89 degrees");
  FinishedView out;
  out.view = synth_->render(model_.camera(base_, yaw_deg, pitch_deg), options_.synthesis).view;
  switch (options_.background.kind) {
    case ViewBackground::Kind::Photo:
      out.image = scene_.composite(out.view);
      break;
    case ViewBackground::Kind::Colour:
      out.image = out.view.image;
      break;
    case ViewBackground::Kind::Transparent:
      out.image = with_alpha(out.view);
      break;
  }
  return out;
}

cv::Mat view_image(const Reconstruction& reconstruction, const ViewOptions& options, double yaw_deg,
                   double pitch_deg) {
  return ViewRenderer(reconstruction, options).image(yaw_deg, pitch_deg);
}

}  // namespace orthoface::reconstruct
