#include "vision/observe_front.h"

#include <optional>

#include "vision/face_landmarks68.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "vision/contour_chain.h"
#include "vision/edges.h"
#include "vision/foreground.h"
#include "vision/front_boundary.h"
#include "vision/front_features.h"
#include "vision/haar_init.h"
#include "vision/ibug68.h"
#include "vision/landmarks.h"

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
      if ((c.x > face->x + face->width / 2.0) != image_right || c.y > face->y + face->height * 0.6)
        continue;
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

// The centre line through the midpoints of the eye centres, mouth corners and nose wings (each
// pair where both are in `f`), roll from the eye centres; none without both eye centres.
std::optional<CentreLine> centre_from_pairs(const std::map<std::string, Feature2d>& f) {
  const Feature2d* eye_r = find_feature(f, "eye_right_center");
  const Feature2d* eye_l = find_feature(f, "eye_left_center");
  if (!eye_r || !eye_l || eye_l->px.x == eye_r->px.x) return std::nullopt;
  cv::Point2d mid(0, 0);
  int pairs = 0;
  for (const auto& [r, l] :
       {std::pair<const char*, const char*>{"eye_right_center", "eye_left_center"},
        {"mouth_right", "mouth_left"},
        {"alar_right", "alar_left"}}) {
    const Feature2d* a = find_feature(f, r);
    const Feature2d* b = find_feature(f, l);
    if (a && b) mid += (a->px + b->px) / 2, ++pairs;
  }
  CentreLine c;
  c.centre_x = mid.x / pairs;
  c.centre_y = mid.y / pairs;
  c.roll_rad = std::atan(-(eye_l->px.y - eye_r->px.y) / (eye_l->px.x - eye_r->px.x));
  c.confidence = 1.0;
  return c;
}

// A square around where the face should be in the head blob, for when the Haar cascade finds
// none: centred on the boundary's middle at 60 % of its height, 0.8 head widths wide.
cv::Rect2d face_guess(const FrontBoundary& fb) {
  const double top = fb.top_row, bottom = fb.bottom_row, h = bottom - top;
  const double row = top + 0.45 * h;
  const double l = boundary_x(fb.left, row), r = boundary_x(fb.right, row);
  const double w = 0.8 * (r - l);
  return {0.5 * (l + r) - w / 2, top + 0.6 * h - w / 2, w, w};
}

// Replaces the filters' eyes, brows, nose, mouth, chin and midline rows by the network's, and
// the centre line by the one through its symmetric pairs; under Consensus, keeps the filters'
// midline and every filters' point the network confirms (see FrontLandmarker). Leaves `ff` as it
// was (with a warning) when the weights cannot be read or no plausible face is found.
void network_landmarks(const cv::Mat& front, const FrontBoundary& fb, const FrontFace& face,
                       const ObserveOptions& o, FrontFeatures& ff,
                       std::map<std::string, Feature2d>& trained,
                       std::vector<cv::Point2d>& points68, std::vector<std::string>& warn) {
  const FaceLandmarker68* net = shared_landmarker();
  if (!net) {
    warn.push_back("front landmarks: the network's weights are missing (" + default_model_dir() +
                   "); the filters' features are used");
    return;
  }
  std::optional<FaceLandmarks68> found = face.found;
  try {
    if (!found) found = net->detect_in(front, face_guess(fb), 6);
  } catch (const std::invalid_argument&) {  // a silhouette too thin to hold a face crop
    warn.push_back(
        "front landmarks: no face crop in the head's silhouette; the filters' features are used");
    return;
  }
  const auto& p = found->points;
  const double row = 0.5 * (p[36].y + p[45].y);
  const double head_w = boundary_x(fb.right, row) - boundary_x(fb.left, row);
  const double eyes_w = cv::norm(p[45] - p[36]);
  const bool inside = p[36].x > boundary_x(fb.left, row) && p[45].x < boundary_x(fb.right, row);
  if (!(found->movement_px < 0.05 * eyes_w && eyes_w > 0.3 * head_w && eyes_w < 0.9 * head_w &&
        inside)) {
    warn.push_back(
        "front landmarks: the network found no plausible face; the filters' features are used");
    return;
  }
  const cv::Point2d half(0.5, 0.5);  // network points: continuous, origin at the pixel corner
  auto feature = [&](cv::Point2d q) {
    Feature2d f;
    f.px = q - half;
    f.confidence = 0.9;
    f.method = "network-68";
    return f;
  };
  const FrontFeatures filters = ff;
  Ibug68 all;
  std::copy(p.begin(), p.end(), all.begin());
  for (const auto& [name, q] : named_from_ibug68(all))
    trained[name] = ff.features[name] = feature(q);
  if (const auto c = centre_from_pairs(ff.features)) ff.centre = *c;
  points68.assign(p.begin(), p.end());
  const cv::Point2d mid(ff.centre.centre_x, ff.centre.centre_y);
  if (o.landmarker != FrontLandmarker::Consensus) return;
  // Consensus: a filters' point the network confirms is kept (it sits on the photo's own edge);
  // the midline keeps the profile's rows, so the two photos agree on its heights.
  // The network's brows lie on the brow's upper edge and its nose wings at the nostril's base
  // (iBUG); the base mesh's on the brow's middle and the wing's outermost point. Measured on the
  // sim heads (median offset over 12, fraction of the eye distance): brows 0.05 high, wings 0.07
  // inward and 0.03 low.
  for (const char* b : {"brow_left_inner", "brow_left_center", "brow_left_outer",
                        "brow_right_inner", "brow_right_center", "brow_right_outer"})
    ff.features[b].px.y += 0.05 * eyes_w;
  ff.features["alar_left"].px += cv::Point2d(0.07, -0.03) * eyes_w;  // image-right wing
  ff.features["alar_right"].px += cv::Point2d(-0.07, -0.03) * eyes_w;
  const double tol = 0.06 * eyes_w;
  for (auto& [name, f] : ff.features) {
    const auto it = filters.features.find(name);
    if (it == filters.features.end()) continue;
    const bool midline = mirrored_name(name) == name;
    const bool agree = !it->second.mirrored && cv::norm(it->second.px - f.px) < tol;
    if (midline || agree) f = it->second;
  }
  const double filters_x = filters.centre.centre_x +
                           std::tan(filters.centre.roll_rad) * (mid.y - filters.centre.centre_y);
  if (std::abs(filters_x - mid.x) < tol) ff.centre = filters.centre;
}

// x of the polyline `jaw` (top to bottom) at row y; NaN outside its rows.
double polyline_x(const std::vector<cv::Point2d>& jaw, double y) {
  for (size_t i = 1; i < jaw.size(); ++i) {
    const cv::Point2d a = jaw[i - 1], b = jaw[i];
    if (y >= std::min(a.y, b.y) && y <= std::max(a.y, b.y) && b.y != a.y)
      return a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

// The face's own outline where the head's silhouette is not the face: hair hanging beside the
// cheeks, a hood or a collar up to the jaw widen the silhouette, and seed 004's slices would
// take that width as the face's (a flat, wide lower face that shows at every turn). From the
// cheekbone (iBUG jaw points 1 / 15) to the jaw's corner (5 / 11) a boundary point lying more
// than 0.12 eye widths outside the network's jaw line moves onto it (the sim heads' jaw line, which
// lies on their silhouette, stays within that); below the jaw's corner the boundary is
// kept no wider than there (the neck is narrower than the jaw). Returns how many rows moved.
int fit_boundary_to_jaw(FrontBoundary& fb, const std::vector<cv::Point2d>& p68) {
  if (p68.size() != 68) return 0;
  const cv::Point2d half(0.5, 0.5);
  const double eyes_w = cv::norm(p68[45] - p68[36]);
  const double tol = 0.12 * eyes_w, margin = 0.02 * eyes_w;
  int moved = 0;
  // Image-left side: jaw points 0..8, outward is -x; image-right: 16..8, outward +x.
  for (const int outward : {-1, 1}) {
    std::vector<cv::Point2d> jaw;
    for (int k = 0; k <= 8; ++k) jaw.push_back(p68[outward < 0 ? k : 16 - k] - half);
    const double top = jaw[1].y, corner = jaw[5].y;
    auto& side = outward < 0 ? fb.left : fb.right;
    double corner_x = std::numeric_limits<double>::quiet_NaN();
    for (auto& b : side) {
      if (b.y < top) continue;
      if (b.y <= corner) {
        const double jaw_x = polyline_x(jaw, b.y);
        if (!std::isfinite(jaw_x)) continue;
        const double limit = jaw_x + outward * margin;
        if (outward * (b.x - limit) > tol) b.x = limit, ++moved;
        corner_x = b.x;
      } else if (std::isfinite(corner_x) && outward * (b.x - corner_x) > 0) {
        b.x = corner_x, ++moved;
      }
    }
  }
  return moved;
}

// The user's front landmarks (options.front_landmarks, capture convention) replace the detected
// ones, in the features and in `trained` (both the features' true positions, which head-turn
// estimation and the input check read). When they give a symmetric pair the centre line uses,
// it is re-fitted through the pairs as the network's is, so the midline follows the user.
void user_landmarks(const ObserveOptions& o, FrontFeatures& ff,
                    std::map<std::string, Feature2d>& trained) {
  bool pair_given = false;
  for (const auto& [name, px] : o.front_landmarks) {
    Feature2d f;
    f.px = px - cv::Point2d(0.5, 0.5);  // index coordinates, as ff
    f.confidence = 1.0;
    f.method = "user";
    ff.features[name] = trained[name] = f;
    for (const char* n : {"eye_right_center", "mouth_right", "alar_right"})
      if (name == n && o.front_landmarks.count(mirrored_name(n))) pair_given = true;
  }
  if (!pair_given) return;
  if (const auto c = centre_from_pairs(ff.features)) ff.centre = *c;
}

}  // namespace

FrontHead segment_front(const cv::Mat& front, const cv::Mat& bg) {
  FrontHead h;
  h.probability = foreground_probability(front, bg);
  h.mask = head_mask(h.probability, {}, &h.blobs);
  return h;
}

FrontFace find_front_face(const cv::Mat& front, const ObserveOptions& o, const cv::Rect& within,
                          const std::function<void(const FaceLandmarks68&)>& first_pass) {
  if (front.empty() || front.type() != CV_8UC3)
    throw std::invalid_argument("front face: the front photo must be a non-empty 8-bit BGR image");
  FrontFace f;
  const FaceLandmarker68* net = shared_landmarker();
  if (!net || o.landmarker == FrontLandmarker::Filters) return f;
  try {
    // Four passes: against dlib's points on the 26 FRMDB fronts (13 points, fraction of the eye
    // distance) 0.080 after one, 0.054, 0.0503, 0.0498 after four; with three the real-photo
    // judge's mean face score at +-45 fell from 0.593 to 0.543.
    if (const auto box = haar_face(front, o.haar_dir, false, within)) {
      const FaceLandmarks68 first = net->detect_in(front, cv::Rect2d(*box), 0);
      if (first_pass) first_pass(first);
      f.found = net->refine(front, first, 3);
    }
  } catch (const std::invalid_argument&) {  // no crop to refine: observe_front() tries its own
  }
  return f;
}

void observe_front(const cv::Mat& front, const cv::Mat& bg, const FrontHead& head,
                   const FrontFace& face, const SideProfile& sp, double row_scale,
                   const ObserveOptions& o, FaceObservation& obs) {
  auto& warn = obs.warnings;
  const cv::Mat& prob = head.probability;
  const cv::Mat& mask = head.mask;
  const int blobs = head.blobs;
  if (mask.empty()) {
    warn.push_back(bg.empty() ? cut_off_border(front) : std::string());
    if (warn.back().empty())
      warn.back() = "front view: no head found (no subject distinct from the background)";
    return;
  }
  if (blobs > 1)
    warn.push_back("front view: " + std::to_string(blobs) + " heads; using the central one");
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
  if (o.use_haar && o.landmarker != FrontLandmarker::Network) haar_assist(front, o, ff, warn);
  std::map<std::string, Feature2d> trained;
  if (o.landmarker != FrontLandmarker::Filters)
    network_landmarks(front, fb, face, o, ff, trained, obs.front_points68, warn);
  if (!o.front_landmarks.empty()) user_landmarks(o, ff, trained);
  for (const auto& w : ff.warnings) warn.push_back(w);
  // A cheek (at the nose tip's row, from the boundary) whose row moved onto the jaw line moves
  // with it.
  const FrontBoundary silhouette = fb;
  if (fit_boundary_to_jaw(fb, obs.front_points68) > 0)
    for (const char* n : {"cheek_right", "cheek_left"}) {
      auto it = ff.features.find(n);
      if (it == ff.features.end()) continue;
      const bool image_left = n[6] == 'r';  // cheek_right lies on the image's left
      const double y = it->second.px.y, inward = image_left ? 1.0 : -1.0;
      const double x = boundary_x(image_left ? fb.left : fb.right, y);
      const double was = boundary_x(image_left ? silhouette.left : silhouette.right, y);
      if (inward * (x - was) > 0.5 && inward * (x - it->second.px.x) > 0) it->second.px.x = x;
    }
  for (const auto& p : fb.left) obs.front.boundary.push_back(out_px(p));
  for (const auto& p : fb.right) obs.front.boundary.push_back(out_px(p));
  obs.front.boundary_confidence = fb.confidence;
  for (const auto& [n, f] : ff.features) {
    Feature2d g = f;
    g.px = out_px(f.px);
    obs.front.features[n] = g;
  }
  for (auto [n, f] : trained) {
    f.px = out_px(f.px);
    obs.front_trained[n] = f;
  }
  obs.centre_x_px = ff.centre.centre_x + 0.5;
  obs.centre_y_px = ff.centre.centre_y + 0.5;
  obs.roll_rad = ff.centre.roll_rad;
  obs.centre_confidence = ff.centre.confidence;
}

}  // namespace orthoface::vision
