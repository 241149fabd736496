// The scene composited views are drawn into: the front photo without the head (render/composite.h).
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "reconstruct/reconstruction.h"
#include "render/composite.h"
#include "render/new_view.h"

namespace orthoface::reconstruct {
namespace {

// Row of the chin's lowest point in the front photo: the landmark, else the face mesh's lowest
// vertex.
double chin_row(const Reconstruction& r) {
  for (const char* name : {"chin_bottom", "chin"}) {
    const auto it = r.landmarks.find(name);
    if (it != r.landmarks.end()) return capture::project(r.photo_rig.front, it->second).y();
  }
  double row = -std::numeric_limits<double>::infinity();
  for (const auto& v : r.mesh.vertices)
    row = std::max(row, capture::project(r.photo_rig.front, v).y());
  return row;
}

// Row of the mouth's corners in the front photo; NaN without them.
double mouth_row(const Reconstruction& r) {
  double sum = 0;
  int n = 0;
  for (const char* name : {"mouth_left", "mouth_right"}) {
    const auto it = r.landmarks.find(name);
    if (it == r.landmarks.end()) continue;
    sum += capture::project(r.photo_rig.front, it->second).y();
    ++n;
  }
  return n ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

// Where the subject (hair, clothes) rather than the background surrounds the removed region (long
// hair round the face), `background`'s fill (from the background alone: dark curtain in the hair
// beside a turned face) gives way to a fill from everything around, by the share of the subject
// among the photo's own pixels nearby (normalised convolution of the two masks).
void fill_inside_hair(const cv::Mat& photo, const cv::Mat& removed, const cv::Mat& silhouette,
                      cv::Mat& background) {
  const cv::Mat around = render::head_removed(photo, removed);
  const cv::Mat known = removed == 0;
  const double sigma = std::max(2.0, 0.03 * photo.cols);
  cv::Mat k, s;
  known.convertTo(k, CV_32F, 1.0 / 255);
  cv::Mat(silhouette & known).convertTo(s, CV_32F, 1.0 / 255);
  cv::GaussianBlur(k, k, cv::Size(0, 0), sigma);
  cv::GaussianBlur(s, s, cv::Size(0, 0), sigma);
  for (int y = 0; y < photo.rows; ++y) {
    const auto* hole = removed.ptr<uchar>(y);
    const auto* kk = k.ptr<float>(y);
    const auto* ss = s.ptr<float>(y);
    const auto* a = around.ptr<cv::Vec3b>(y);
    auto* b = background.ptr<cv::Vec3b>(y);
    for (int x = 0; x < photo.cols; ++x) {
      if (!hole[x] || kk[x] < 1e-4f) continue;
      const float w = std::clamp(ss[x] / kk[x], 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c)
        b[x][c] = cv::saturate_cast<uchar>((1 - w) * b[x][c] + w * a[x][c]);
    }
  }
}

}  // namespace

cv::Mat ViewScene::composite(const render::RenderResult& view) const {
  render::CompositeOptions o;
  o.fade_from_row = fade_from_row;
  o.fade_to_row = fade_to_row;
  return render::composite(view, background, o);
}

cv::Mat ViewScene::composite(const render::RenderResult& view, const cv::Mat& frame,
                             int keep_px) const {
  if (frame.size() != background.size() || frame.type() != background.type())
    throw std::invalid_argument("composite: the frame must be 8-bit BGR of the scene's size");
  if (keep_px < 0) throw std::invalid_argument("composite: keep_px must be >= 0");
  ViewScene live = *this;
  live.background = frame.clone();
  if (keep_px > 0 && view.mask.size() == removed.size()) {
    // Only around the removed region (a live frame's budget: the whole frame's dilation costs
    // about 2 ms on two cores).
    const cv::Rect box = cv::boundingRect(removed);
    const cv::Rect roi = (box + cv::Size(2 * keep_px, 2 * keep_px) - cv::Point(keep_px, keep_px)) &
                         cv::Rect(0, 0, removed.cols, removed.rows);
    if (!roi.empty()) {
      cv::Mat near_head;
      cv::dilate(view.mask(roi), near_head,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * keep_px + 1, 2 * keep_px + 1}));
      cv::Mat fill = removed(roi) & ~near_head;  // a new mask: removed stays as it is
      cv::Mat out = live.background(roi);
      background(roi).copyTo(out, fill);
    }
  } else {
    background.copyTo(live.background, removed);
  }
  return live.composite(view);
}

ViewScene ViewScene::fitted(int width, int height) const {
  ViewScene s = *this;
  s.background = render::fitted(background, width, height);
  s.removed = render::fitted(removed, width, height) > 127;
  const double k = std::min(double(width) / background.cols, double(height) / background.rows);
  const double top = (height - background.rows * k) / 2;
  s.fade_from_row = top + fade_from_row * k;
  s.fade_to_row = top + fade_to_row * k;
  return s;
}

ViewScene view_scene(const Reconstruction& r, render::ViewSynthesizer& synth, bool neck_twists) {
  if (r.front.empty()) throw std::invalid_argument("view_scene: the reconstruction has no photos");
  render::SynthesisOptions quick;
  quick.float_textures = false;
  quick.depth = false;
  const cv::Mat head = synth.render(r.photo_rig.front, quick).view.mask;
  ViewScene scene;
  // The neck: a view whose neck twists back into the body (neck_twists: view_model's turn
  // weights, 1 down to halfway between the chin and the lowest row, 0 there) fades into the
  // photo's own over the neck's lowest fifth (0.8 to 0.97 of the way down from the chin, turn
  // weight 0.35 down to 0); faded from a third of the way down, a neck still turned with the
  // head was blended with the photo's unturned one into a doubled collar
  // (docs/views_accuracy.md). A neck that turns whole with the head fades from a third to 0.8
  // of the way. The photo's own neck and body stay below.
  int bottom = head.rows - 1;
  while (bottom >= 0 && cv::countNonZero(head.row(bottom)) == 0) --bottom;
  const double chin = chin_row(r);
  cv::Mat region = head.clone();
  if (std::isfinite(chin) && bottom > chin + 4) {
    scene.fade_from_row = chin + (neck_twists ? 0.8 : 0.3) * (bottom - chin);
    scene.fade_to_row = chin + (neck_twists ? 0.97 : 0.8) * (bottom - chin);
    // Hair the mesh does not reach goes too (else it shows beside the turned head) down to the
    // chin; below, the view's own neck, and the photo's neck and body below the fade stay.
    // Only near the head: shoulders that rise above the chin stay.
    if (r.front_silhouette.size() == head.size()) {
      const int reach = std::max(3, int(std::lround(0.05 * head.cols)));
      cv::Mat near_head;
      cv::dilate(head, near_head,
                 cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * reach + 1, 2 * reach + 1}));
      cv::Mat hair = r.front_silhouette & near_head;
      hair.rowRange(std::clamp(int(std::ceil(chin)), 0, head.rows), head.rows).setTo(0);
      region |= hair;
    }
    const int keep = std::clamp(int(std::ceil(scene.fade_from_row)), 0, head.rows);
    region.rowRange(keep, head.rows).setTo(0);
  }
  // Past the head's edge (its anti-aliased fringe, GrabCut's few pixels of doubt) the photo goes
  // too, and the subject's own edge stays out of the fill.
  const int grow = std::max(4, int(std::lround(0.012 * head.cols)));
  const cv::Mat ring = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * grow + 1, 2 * grow + 1});
  cv::dilate(region > 0, scene.removed, ring);
  cv::Mat subject;
  if (!r.front_silhouette.empty()) cv::dilate(r.front_silhouette, subject, ring);
  // From the mouth's row down the subject beside the head is clothes and hair, which the removed
  // collar and hair fade into: filled from the background alone they showed as dark bays
  // beside the turned neck.
  const double mouth = mouth_row(r);
  if (!subject.empty() && std::isfinite(mouth))
    subject.rowRange(std::clamp(int(std::ceil(mouth)), 0, subject.rows), subject.rows).setTo(0);
  scene.background = render::head_removed(r.front, scene.removed, r.front_plate, subject);
  if (r.front_plate.empty() && !subject.empty())
    fill_inside_hair(r.front, scene.removed, r.front_silhouette, scene.background);
  return scene;
}

}  // namespace orthoface::reconstruct
