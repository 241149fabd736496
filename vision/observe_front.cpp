#include "vision/observe_front.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "vision/contour_chain.h"
#include "vision/edges.h"
#include "vision/front_boundary.h"
#include "vision/front_features.h"
#include "vision/haar_init.h"
#include "vision/landmarks.h"
#include "vision/segment.h"

namespace orthoface::vision {

namespace {

cv::Point2d out_px(cv::Point2d p) { return p + cv::Point2d(0.5, 0.5); }

// A profile given as the front photo: one silhouette side has a nose bump, the other not.
void check_not_profile(const cv::Mat& mask, std::vector<std::string>& warn) {
  const RowExtent e = row_extent(mask);
  double w = 0;
  for (int r = e.top; r >= 0 && r <= e.bottom; ++r)
    if (e.left[r] >= 0) w = std::max(w, double(e.right[r] - e.left[r]));
  const double H = 1.3 * w;
  const cv::Point2d p = side_protrusions(e, int(e.top + 0.3 * H), int(e.top + 0.85 * H));
  const double hi = std::max(p.x, p.y), lo = std::max(1.0, std::min(p.x, p.y));
  const double neck = std::abs(neck_offset(e, H / 1.2));
  // Real frontal photos (hair, turned heads) can look lopsided too, so this only warns.
  if (hi > 0.06 * H && hi / lo > 2.5 && neck > 0.05 * H)
    warn.push_back("front view: silhouette looks like a profile (nose-like bump of " +
                   std::to_string(int(hi)) + " px on one side, " + std::to_string(int(lo)) +
                   " px on the other); were --front and --side swapped?");
  else if (hi > 0.04 * H && hi / lo > 1.6)
    warn.push_back("front view: silhouette is asymmetric; the head may be turned");
}

// No head against the border colours: when leaving one side strip out of the background model
// reveals a head touching that side, the head is cut off there (its colours fill the strip).
std::string cut_off_border(const cv::Mat& front) {
  for (int side = 0; side < 2; ++side) {
    SegmentOptions so;
    (side == 0 ? so.sample_left : so.sample_right) = false;
    const cv::Mat m = head_mask(foreground_probability(front, {}, so), so);
    if (m.empty()) continue;
    const cv::Mat edge = m.col(side == 0 ? 0 : m.cols - 1);
    if (cv::countNonZero(edge) > 0.1 * m.rows)
      return std::string("front view: head cut off by the ") + (side == 0 ? "left" : "right") +
             " image border (no background seen there); move the camera or the subject";
  }
  return {};
}

// Optional Haar check (never the default): a frontal face box should hold the eyes; when an eye
// was only mirrored, a Haar eye inside the face box replaces it.
void haar_assist(const cv::Mat& front, const ObserveOptions& o, FrontFeatures& ff,
                 std::vector<std::string>& warn) {
  const auto face = haar_face(front, o.haar_dir, false);
  if (!face) {
    warn.push_back("haar: no frontal face found by the cascade");
    return;
  }
  const auto eyes = haar_eyes(front, *face, o.haar_dir);
  for (const char* name : {"eye_left_center", "eye_right_center"}) {
    auto it = ff.features.find(name);
    const bool image_right = std::string(name) == "eye_left_center";
    for (const cv::Rect& r : eyes) {
      const cv::Point2d c(r.x + r.width / 2.0, r.y + r.height / 2.0);
      if ((c.x > face->x + face->width / 2.0) != image_right || c.y > face->y + face->height * 0.6) continue;
      if (it == ff.features.end() || it->second.mirrored) {
        Feature2d f;
        f.px = c;
        f.confidence = 0.5;
        f.method = "haar";
        ff.features[name] = f;
      }
      break;
    }
  }
}

}  // namespace

FrontHead segment_front(const cv::Mat& front, const cv::Mat& bg) {
  FrontHead h;
  h.probability = foreground_probability(front, bg);
  h.mask = head_mask(h.probability, {}, &h.blobs);
  return h;
}

void observe_front(const cv::Mat& front, const cv::Mat& bg, const FrontHead& head,
                   const SideProfile& sp, double row_scale, const ObserveOptions& o,
                   FaceObservation& obs) {
  auto& warn = obs.warnings;
  const cv::Mat& prob = head.probability;
  const cv::Mat& mask = head.mask;
  const int blobs = head.blobs;
  if (mask.empty()) {
    warn.push_back(bg.empty() ? cut_off_border(front) : std::string());
    if (warn.back().empty()) warn.back() = "front view: no head found (no subject distinct from the background)";
    return;
  }
  if (blobs > 1) warn.push_back("front view: " + std::to_string(blobs) + " heads; using the central one");
  check_not_profile(mask, warn);
  std::map<std::string, double> rows;
  for (const auto& [n, f] : sp.features)
    rows[n] = (f.px.y + 0.5) * row_scale - 0.5;  // shared row (seed 004 eq. 1)
  const double H = sp.head_height_px * row_scale;
  int bottom = -1;
  if (rows.count("chin_bottom")) bottom = int(rows["chin_bottom"] + 0.08 * H);
  FrontBoundary fb = front_boundary(prob, mask, bottom);
  for (const auto& w : fb.warnings) warn.push_back(w);
  if (fb.left.empty() || fb.right.empty()) return;
  // The probability's smoothing widens the blob by about a pixel: each row's boundary goes to
  // the photo's own colour step nearby (the rows stay: the search runs along them).
  for (auto* side : {&fb.left, &fb.right})
    *side = snap_to_colour_step(front, *side, std::vector<cv::Point2d>(side->size(), {1.0, 0.0}));
  FrontFeatures ff = front_features(front, fb, rows, H);
  if (o.use_haar) haar_assist(front, o, ff, warn);
  for (const auto& w : ff.warnings) warn.push_back(w);
  for (const auto& p : fb.left) obs.front.boundary.push_back(out_px(p));
  for (const auto& p : fb.right) obs.front.boundary.push_back(out_px(p));
  obs.front.boundary_confidence = fb.confidence;
  for (const auto& [n, f] : ff.features) {
    Feature2d g = f;
    g.px = out_px(f.px);
    obs.front.features[n] = g;
  }
  obs.centre_x_px = ff.centre.centre_x + 0.5;
  obs.centre_y_px = ff.centre.centre_y + 0.5;
  obs.roll_rad = ff.centre.roll_rad;
  obs.centre_confidence = ff.centre.confidence;
}

}  // namespace orthoface::vision
