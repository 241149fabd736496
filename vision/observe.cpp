#include "vision/observe.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/contour_chain.h"
#include "vision/face_detect.h"
#include "vision/face_landmarks68.h"
#include "vision/feature_filters.h"
#include "vision/foreground.h"
#include "vision/front_boundary.h"
#include "vision/front_features.h"
#include "vision/haar_init.h"
#include "vision/image_prep.h"
#include "vision/landmarks.h"
#include "vision/observe_front.h"
#include "vision/registration.h"
#include "vision/scene_cut.h"
#include "vision/side_profile.h"

namespace orthoface::vision {

SideCamera parse_side_camera(const std::string& name) {
  if (name == "auto") return SideCamera::Auto;
  if (name == "left") return SideCamera::Left;
  if (name == "right") return SideCamera::Right;
  throw std::invalid_argument("side camera must be auto, left or right, got '" + name + "'");
}

FrontLandmarker parse_front_landmarker(const std::string& name) {
  if (name == "filters") return FrontLandmarker::Filters;
  if (name == "network") return FrontLandmarker::Network;
  if (name == "consensus") return FrontLandmarker::Consensus;
  throw std::invalid_argument("front landmarker must be filters, network or consensus, got '" +
                              name + "'");
}

const char* front_landmarker_name(FrontLandmarker landmarker) {
  switch (landmarker) {
    case FrontLandmarker::Network:
      return "network";
    case FrontLandmarker::Consensus:
      return "consensus";
    case FrontLandmarker::Filters:
      break;
  }
  return "filters";
}

void ObserveOptions::check() const {
  if (!(max_size_ratio >= 1.0 && max_size_ratio <= 10.0))
    throw std::invalid_argument("ObserveOptions: max_size_ratio must be in [1, 10]");
  for (const auto& [name, px] : front_landmarks) {
    if (!is_landmark_name(name))
      throw std::invalid_argument("ObserveOptions: front landmark '" + name +
                                  "' is not a landmark name (vision/landmarks.h)");
    if (!std::isfinite(px.x) || !std::isfinite(px.y))
      throw std::invalid_argument("ObserveOptions: front landmark '" + name + "' is not finite");
  }
}

namespace {

constexpr double kHeightPerWidth = 1.25;  // crown-to-chin height / head width, lower bound
// A side photo's face turned at least this much (turn index, about 20 degrees) says which way
// the profile looks.
constexpr double kClearSideTurn = 0.3;
// The side photo's face is searched from a quarter of its shorter side (1/7 x 1.2^3) up, in
// three quarters of the time of a search from a fifth (FRMDB's 45-degree faces are 0.39 of it);
// the faces of that size score as in the full search the input check's limits were set on.
constexpr int kSideFaceCoarserLevels = 3;

// Index coordinates -> capture convention (pixel centre = index + 0.5).
cv::Point2d out_px(cv::Point2d p) { return p + cv::Point2d(0.5, 0.5); }

// The user's front landmarks must lie in the front image (capture convention: 0..width).
void check_user_landmarks(const ObserveOptions& o, const cv::Mat& front) {
  for (const auto& [name, px] : o.front_landmarks)
    if (!(px.x >= 0 && px.y >= 0 && px.x <= front.cols && px.y <= front.rows))
      throw std::invalid_argument("front landmark '" + name + "' at (" + std::to_string(px.x) +
                                  ", " + std::to_string(px.y) + ") lies outside the " +
                                  std::to_string(front.cols) + "x" + std::to_string(front.rows) +
                                  " front image");
}

struct SideResult {
  SideProfile profile;  // in the image as given (un-mirrored), index coordinates
  bool faces_left = true;
  double facing_confidence = 0;
  bool seen_faces_left = true;  // as the image shows it, whatever --side-camera said
  double seen_confidence = 0;
};

// Where a photo's face is searched: around its head blob (a fifth of the blob's size beyond it
// on each side), or the whole photo when there is no blob.
cv::Rect search_area(const cv::Mat& mask) {
  if (mask.empty() || cv::countNonZero(mask) == 0) return {};
  const cv::Rect b = cv::boundingRect(mask);
  const int mx = b.width / 5, my = b.height / 5;
  return cv::Rect(b.x - mx, b.y - my, b.width + 2 * mx, b.height + 2 * my) &
         cv::Rect(0, 0, mask.cols, mask.rows);
}

// The side photo's foreground probability and head blob: they need nothing from the front view.
struct SideBlob {
  cv::Mat prob, mask;
  int blobs = 0;
};
SideBlob side_blob(const cv::Mat& side, const cv::Mat& bg) {
  SideBlob b;
  b.prob = foreground_probability(side, bg);
  b.mask = head_mask(b.prob, {}, &b.blobs);
  return b;
}

SideResult observe_side(const cv::Mat& side, const SideBlob& blob, SideCamera cam,
                        double min_head_height_px, double expected_nose_row,
                        std::vector<std::string>& warn) {
  SideResult r;
  const cv::Mat &prob = blob.prob, &mask = blob.mask;
  const int blobs = blob.blobs;
  if (mask.empty()) {
    warn.push_back("side view: no head found (no subject distinct from the background)");
    return r;
  }
  if (blobs > 1)
    warn.push_back("side view: " + std::to_string(blobs) + " heads; using the central one");
  r.faces_left = profile_faces_left(mask, side, &r.facing_confidence, min_head_height_px);
  r.seen_faces_left = r.faces_left, r.seen_confidence = r.facing_confidence;
  if (cam != SideCamera::Auto)
    r.faces_left = cam == SideCamera::Left, r.facing_confidence = 1;
  else if (r.facing_confidence < 0.3)
    warn.push_back("side view: facing direction unsure; give --side-camera left|right");
  // A right-facing profile is mirrored into fresh buffers (flipping into a header of `side`
  // would mirror `side` itself in place, and observe() reads it again afterwards).
  cv::Mat im, pr, mk;
  if (r.faces_left)
    im = side, pr = prob, mk = mask;
  else
    cv::flip(side, im, 1), cv::flip(prob, pr, 1), cv::flip(mask, mk, 1);
  SideProfileOptions so;
  so.min_head_height_px = min_head_height_px;
  so.expected_nose_row = expected_nose_row;
  r.profile = side_profile(im, pr, mk, so);
  if (!r.faces_left) {
    const double w1 = side.cols - 1;
    for (auto& p : r.profile.curve) p.x = w1 - p.x;
    for (auto& [n, f] : r.profile.features) f.px.x = w1 - f.px.x;
  }
  for (const auto& w : r.profile.warnings) warn.push_back(w);
  return r;
}

// What the side photo's work learns from the front once its face is found (vision/
// scene_cut.h): where the head is and what colours it has, whether the front was cut out of a
// busy scene (the side then is too), and the least head height of that cut.
struct FrontHint {
  std::optional<SideHint> head;
  bool front_cut = false;
  bool front_plate = false;  // the front was cut by its clean plate: no rule of the side's moves it
  double min_h = 0;
};

// Everything observe() learns from the side photo alone, and its profile once the front blob
// gives the least head height (`min_h`: the front blob's head width, as a side blob without its
// hair underestimates it); then, told where the front's head is (`front`), the profile again
// when the side photo must be cut out of a busy scene.
struct SideWork {
  SideBlob blob;
  FoundFace face;
  SideCamera camera = SideCamera::Auto;  // as given, or as the face found decided
  SideResult result;
  bool cut = false;   // cut out of a busy scene (its own border or the front's cut said so)
  bool busy = false;  // its scene is busy (its own border or blob said so), plate or not
  std::vector<std::string> warnings;
};
SideWork side_work(const cv::Mat& side, const cv::Mat& bg, SideCamera given,
                   std::shared_future<double> min_h, std::shared_future<double> nose_row,
                   std::shared_future<FrontHint> front) {
  SideWork w;
  w.blob = side_blob(side, bg);
  w.face = find_face(side, kSideFaceCoarserLevels);
  // A face found in the side photo points the way the profile looks (its nose toward the image
  // left: turn index < 0): with --side-camera auto a clear turn decides, before the silhouette's
  // cues, which a skin-only blob (hair as dark as the background) can mislead.
  w.camera = given;
  if (given == SideCamera::Auto && std::abs(w.face.turn) >= kClearSideTurn)
    w.camera = w.face.turn < 0 ? SideCamera::Left : SideCamera::Right;
  std::vector<std::string> warnings;
  // The side photo's own border, measured while the front's work may still run.
  const int colours = border_colour_count(side);
  w.result = observe_side(side, w.blob, w.camera, min_h.get(), nose_row.get(), warnings);
  const FrontHint& hint = front.get();
  // The side's scene is busy when its border is or when the border colours' blob leaves out the
  // subject's colours (skin-coloured walls, wood). With a plate the side is cut by difference,
  // and what its border says still tells the front (one room).
  double missed = 0;
  if (hint.head && (bg.empty() || !hint.front_plate)) {
    missed = side_missed(side, bg.empty() ? w.blob.mask : side_blob(side, {}).mask, *hint.head);
    w.busy = colours > kBusyBorderColours || missed > kSideMissed;
  }
  if (hint.head && bg.empty()) {
    // The side is cut out like the front (the same room), or when its own scene is busy.
    if (hint.front_cut || w.busy) {
      const SceneCut cut = cut_side(side, *hint.head, w.blob.prob);
      w.blob.prob = cut.probability, w.blob.mask = cut.mask;
      w.blob.blobs = cut.mask.empty() ? 0 : 1;
      w.cut = true;
      if (!hint.front_cut)
        w.warnings.push_back("side view: busy background (" +
                             (colours > kBusyBorderColours
                                  ? std::to_string(colours) + " colours along the photo's border"
                                  : "the head's blob leaves out " +
                                        std::to_string(int(std::lround(100 * missed))) +
                                        " % of the subject's colours") +
                             "): the subject was cut out where its colours gather; a clean plate "
                             "(--side-background) does better");
      warnings.clear();
      w.result = observe_side(side, w.blob, w.camera, hint.min_h, nose_row.get(), warnings);
    }
  }
  for (auto& m : warnings) w.warnings.push_back(std::move(m));
  return w;
}

// Ear of the side camera's side from a position model relative to the nose tip (seed 004 §4
// position model; the ear itself is weakly textured, so confidence stays low). Scaled by the
// front photo's outer-eye distance carried into the side photo's pixels (the rows'
// registration) rather than by the side blob's head height, which hair and collars inflate.
// The tragus: 1.51 outer-eye distances behind the tip and 0.05 below it, the medians of the
// tragus placed by hand on 24 FRMDB profiles (spreads 0.14 and 0.17; docs/views_accuracy.md).
// The ear's top keeps the head-height model's offset from the tragus, converted at that set's
// median H = 2.54 eye distances (not measured). Without both eye corners the head height
// scales it as before.
void add_side_ears(const SideResult& s, const FaceObservation& obs,
                   std::map<std::string, Feature2d>& f) {
  const auto tip = s.profile.features.find("nose_tip");
  if (tip == s.profile.features.end()) return;
  const double H = s.profile.head_height_px, dir = s.faces_left ? 1 : -1;
  const std::string side = s.faces_left ? "left" : "right";
  const auto& front = obs.front.features;
  const auto eye_l = front.find("eye_left_outer"), eye_r = front.find("eye_right_outer");
  double back = 0.48 * H, down = -0.085 * H, top_back = 0.10 * H, top_up = 0.145 * H;
  if (eye_l != front.end() && eye_r != front.end() && eye_l->second.confidence > 0 &&
      eye_r->second.confidence > 0) {
    const double e = cv::norm(eye_l->second.px - eye_r->second.px) * side_row_map(obs).a;
    if (e > 0 && std::isfinite(e))
      back = 1.51 * e, down = 0.05 * e, top_back = 0.25 * e, top_up = 0.37 * e;
  }
  Feature2d t;
  t.px = tip->second.px + cv::Point2d(dir * back, down);
  t.confidence = 0.15;
  t.method = "position-model";
  f["ear_" + side + "_tragus"] = t;
  t.px = tip->second.px + cv::Point2d(dir * (back + top_back), down - top_up);
  f["ear_" + side + "_top"] = t;
}

// The tragi stand out on the front silhouette at the side view's tragus row (shared row).
void add_front_tragi(FaceObservation& obs) {
  for (const auto& [name, f] : obs.side.features) {
    if (name.find("_tragus") == std::string::npos) continue;
    const double row = f.px.y * obs.front.height / std::max(1, obs.side.height);
    for (const char* side : {"left", "right"}) {
      const bool image_right = std::string(side) == "left";  // subject's left = image right
      for (const cv::Point2d& p : obs.front.boundary) {
        if (std::abs(p.y - row) > 0.5 || (p.x > obs.centre_x_px) != image_right) continue;
        Feature2d t = f;
        t.px = p;
        t.method = "boundary+side-row";
        obs.front.features[std::string("ear_") + side + "_tragus"] = t;
        break;
      }
    }
  }
}

// The eye of the side camera's side seen in the profile gives the depth of the eye centre and
// outer corner (stereo mirrors it to the hidden eye), which the front view alone cannot.
void add_side_eye(const cv::Mat& side, const SideResult& s, FaceObservation& obs) {
  const std::string name = s.faces_left ? "left" : "right";
  const auto eye = obs.front.features.find("eye_" + name + "_center");
  const double H = s.profile.head_height_px;
  if (eye == obs.front.features.end() || eye->second.mirrored || s.profile.curve.empty() || H <= 0)
    return;
  // The eye's row in the side photo: the front row through the registration of the two photos
  // (index coordinates).
  const RowMap map = side_row_map(obs);
  const double row = map.a * eye->second.px.y + map.b - 0.5;
  const auto at = std::min_element(
      s.profile.curve.begin(), s.profile.curve.end(),
      [&](cv::Point2d a, cv::Point2d b) { return std::abs(a.y - row) < std::abs(b.y - row); });
  if (std::abs(at->y - row) > 2.0) return;
  const double behind = s.faces_left ? 1.0 : -1.0;
  const cv::Rect box = cv::Rect(cv::Point(int(at->x + behind * 0.2 * H), int(row - 0.1 * H)),
                                cv::Point(int(at->x), int(row + 0.1 * H)));
  const FilterContext ctx = make_filter_context(side, *at, H, box);
  const EyeFound e = find_side_eye(ctx, at->x, row, H, behind);
  if (!e.ok) return;
  // Only the columns are measured here; the rows are the front's, registered.
  Feature2d c;
  c.px = out_px({e.centre.x, row});
  c.confidence = e.confidence;
  c.method = "side-eye-iris";
  obs.side.features["eye_" + name + "_center"] = c;
  const auto outer = obs.front.features.find("eye_" + name + "_outer");
  c.px = {out_px(e.corner_image_right).x,
          outer != obs.front.features.end() ? map.a * outer->second.px.y + map.b : c.px.y};
  c.method = "side-eye-component";
  obs.side.features["eye_" + name + "_outer"] = c;
}

// The network's face box: cheek to cheek (jaw points 0..16), brows to chin (17..26, 8).
cv::Rect2d face_box(const FaceLandmarks68& f) {
  double x0 = 1e9, x1 = -1e9, y0 = 1e9;
  for (int i = 0; i <= 16; ++i) x0 = std::min(x0, f.points[i].x), x1 = std::max(x1, f.points[i].x);
  for (int i = 17; i <= 26; ++i) y0 = std::min(y0, f.points[i].y);
  return cv::Rect2d(x0, y0, x1 - x0, f.points[8].y - y0);
}

// Where the front's head is, for the side photo, from the front's blob; none when the blob falls
// short of the eyes (the side keeps its own).
std::optional<SideHint> head_hint(const cv::Mat& front, const cv::Mat& mask, const cv::Rect2d& box,
                                  double row_scale) {
  if (!(box.width > 1 && box.height > 1)) return std::nullopt;
  try {
    return side_hint(front, mask, box, row_scale);
  } catch (const std::invalid_argument&) {
    return std::nullopt;
  }
}

// The front's subject cut out around the face (vision/scene_cut.h) in place of its border-colour
// blob, `why` saying in the warning what showed the scene busy (`side_too`: the side photo is or
// will be cut as well). False (the blob kept) when the cut falls short of the eyes.
bool cut_front_from_scene(const cv::Mat& front, const cv::Rect2d& box, double row_scale,
                          const std::string& why, bool side_too, FrontHead& head, FrontHint& hint,
                          std::vector<std::string>& warn) {
  const SceneCut cut = cut_front(front, box, head.probability);
  try {
    hint.head = side_hint(front, cut.mask, box, row_scale);
  } catch (const std::invalid_argument&) {  // a cut short of the eyes: keep the blob
    return false;
  }
  head.probability = cut.probability, head.mask = cut.mask, head.blobs = 1;
  hint.front_cut = true;
  warn.push_back("front view: busy background (" + why +
                 "): the subject was cut out around the face" +
                 (side_too ? ", and out of the side photo where its colours gather" : "") +
                 "; clean plates (--front-background / --side-background) do better");
  return true;
}

// Without a clean plate, a front blob that spills into the scene beside the face (vision/
// scene_cut.h) is replaced by the subject cut out around the face; the side learns where the
// front's head is either way, to check its own blob or cut it too.
// `face` was found around the front blob (`searched_blob`) or in the whole photo.
void cut_out_of_scene(const cv::Mat& front, const ObserveOptions& o, double row_scale,
                      bool searched_blob, FrontHead& head, FrontFace& face, FrontHint& hint,
                      std::vector<std::string>& warn) {
  cv::Rect2d box = face_box(*face.found);
  if (!(box.width > 1 && box.height > 1)) return;
  const int colours = border_colour_count(front);
  double spill = scene_spill(head.mask, box);
  // A face found around a blob that is not the head may be the scene's: the largest face of the
  // whole photo is then the one to cut around.
  if (spill > kSceneSpill && searched_blob) {
    FrontFace whole = find_front_face(front, o);
    if (whole.found) {
      face = std::move(whole);
      box = face_box(*face.found);
      spill = scene_spill(head.mask, box);
    }
  }
  if (colours > kBusyBorderColours || spill > kSceneSpill) {
    const std::string why = colours > kBusyBorderColours
                                ? std::to_string(colours) + " colours along the photo's border"
                                : "the head's blob spilled " + std::to_string(spill).substr(0, 4) +
                                      " face areas into the scene";
    if (cut_front_from_scene(front, box, row_scale, why, true, head, hint, warn)) return;
  }
  hint.head = head_hint(front, head.mask, box, row_scale);
}

void check_sizes(const cv::Mat& f, const cv::Mat& s, double ratio) {
  const double r = double(std::max(f.rows, s.rows)) / std::min(f.rows, s.rows);
  if (r > ratio)
    throw std::invalid_argument("front image is " + std::to_string(f.cols) + "x" +
                                std::to_string(f.rows) + " but side image is " +
                                std::to_string(s.cols) + "x" + std::to_string(s.rows) +
                                ": the two views must share the image height (seed 004 eq. 1)");
}

// Byte-equal images (stops at the first differing row; a full L1 norm cost ~2 ms).
bool same_pixels(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  const size_t row_bytes = a.cols * a.elemSize();
  for (int r = 0; r < a.rows; ++r)
    if (std::memcmp(a.ptr(r), b.ptr(r), row_bytes) != 0) return false;
  return true;
}

cv::Mat optional_bgr(const cv::Mat& bg, const cv::Mat& image, const std::string& what) {
  if (bg.empty()) return {};
  cv::Mat b = to_bgr8(bg, what);
  if (b.size() != image.size())
    throw std::invalid_argument(what + ": size " + std::to_string(b.cols) + "x" +
                                std::to_string(b.rows) + " differs from its photo");
  return b;
}

}  // namespace

FaceObservation observe(const cv::Mat& front_in, const cv::Mat& side_in, const ObserveOptions& o) {
  o.check();
  const cv::Mat front = to_bgr8(front_in, "front image");
  const cv::Mat side = to_bgr8(side_in, "side image");
  check_sizes(front, side, o.max_size_ratio);
  check_user_landmarks(o, front);
  if (same_pixels(front, side))
    throw std::invalid_argument(
        "front image and side image are the same picture; the side view "
        "must be taken 90 deg from the front");
  const cv::Mat bgf = optional_bgr(o.background_front, front, "front background");
  const cv::Mat bgs = optional_bgr(o.background_side, side, "side background");
  FaceObservation obs;
  obs.front.width = front.cols, obs.front.height = front.rows;
  obs.side.width = side.cols, obs.side.height = side.rows;
  // The side photo's work (its segmentation, the face it shows, its profile) runs on a second
  // thread while this one segments the front and finds its face. The profile waits for the front
  // blob, whose head width bounds the side view's head height from below (a head is about 1.25x
  // as tall, crown to chin, as it is wide), which a side blob without its hair underestimates (a
  // hood or collar widening the blob below the head does not count), and for the front face's
  // nose row. Told where the front's face is, the side thread checks its blob against the
  // front's head.
  const double row_scale = double(front.rows) / side.rows;
  std::promise<double> min_h_promise, nose_row_promise;
  std::promise<FrontHint> hint_promise;
  std::future<SideWork> side_task =
      std::async(std::launch::async, side_work, std::cref(side), std::cref(bgs), o.side_camera,
                 min_h_promise.get_future().share(), nose_row_promise.get_future().share(),
                 hint_promise.get_future().share());
  const auto min_h = [&](const FrontHead& h) {
    return h.mask.empty() ? 0.0
                          : kHeightPerWidth * head_width(row_extent(h.mask), true) / row_scale;
  };
  FrontHead head;
  FrontFace front_face;
  FrontHint hint;
  bool min_h_set = false, nose_row_set = false;
  try {
    head = segment_front(front, bgf);
    min_h_promise.set_value(min_h(head));
    min_h_set = true;
    // The side profile's nose row comes from the network's first points on the front face (found
    // whichever detector places the front features: the profile must not depend on that choice),
    // handed over before they are refined: the side's profile waits for them alone, not for the
    // refinement or the scene's cut below.
    const auto give_nose_row = [&](const FaceLandmarks68& f) {
      if (nose_row_set) return;
      nose_row_promise.set_value(f.points[30].y / row_scale);
      nose_row_set = true;
    };
    front_face = find_front_face(front, o, search_area(head.mask), give_nose_row);
    bool searched_blob = !head.mask.empty();
    if (!front_face.found && bgf.empty() && searched_blob)  // a blob beside the head
      front_face = find_front_face(front, o, {}, give_nose_row), searched_blob = false;
    if (!nose_row_set && o.landmarker == FrontLandmarker::Filters) {
      ObserveOptions any = o;
      any.landmarker = FrontLandmarker::Consensus;
      find_front_face(front, any, search_area(head.mask), give_nose_row);
    }
    if (!nose_row_set) nose_row_promise.set_value(-1.0), nose_row_set = true;
    if (bgf.empty() && front_face.found)
      cut_out_of_scene(front, o, row_scale, searched_blob, head, front_face, hint, obs.warnings);
    else if (front_face.found)  // cut by its plate: the side learns where the head is all the same
      hint.head = head_hint(front, head.mask, face_box(*front_face.found), row_scale);
    hint.front_plate = !bgf.empty();
    hint.min_h = min_h(head);
    hint_promise.set_value(hint);
  } catch (...) {  // the side's thread must not wait for it
    if (!min_h_set) min_h_promise.set_exception(std::current_exception());
    if (!nose_row_set) nose_row_promise.set_exception(std::current_exception());
    hint_promise.set_exception(std::current_exception());
    throw;
  }
  SideWork side_done = side_task.get();
  // The two cameras stand in one room: a side photo cut out of a busy scene says the front's
  // border colours, few as they were, missed some of it (a pencil or a disc on the desk behind
  // the head joins the front blob, and in a close-up scene_spill's reach lies beyond the frame).
  // A front blob wider than the side's head is deep holds some of the scene too.
  if (!hint.front_cut && bgf.empty() && front_face.found) {
    const cv::Rect2d box = face_box(*front_face.found);
    const double ratio = box.width > 1 && box.height > 1
                             ? head_width_to_depth(head.mask, side_done.blob.mask, box, row_scale)
                             : 0.0;
    if (side_done.busy)
      cut_front_from_scene(front, box, row_scale, "the side photo's scene is", true, head, hint,
                           obs.warnings);
    else if (ratio > kSceneWidthToDepth)
      cut_front_from_scene(front, box, row_scale,
                           "the head's blob is " + std::to_string(ratio).substr(0, 4) +
                               " times as wide as the side photo's head is deep",
                           false, head, hint, obs.warnings);
  }
  obs.side_face = side_done.face;
  obs.front_blob = head.mask;
  obs.side_blob = side_done.blob.mask;
  for (auto& w : side_done.warnings) obs.warnings.push_back(std::move(w));
  const SideResult& s = side_done.result;
  if (side_done.camera != o.side_camera && s.seen_faces_left != s.faces_left &&
      s.seen_confidence >= 0.3)
    obs.warnings.push_back(
        "side view: the face found in it looks the other way than the silhouette suggests; "
        "the face decided (give --side-camera left|right to say)");
  obs.side_faces_left = s.faces_left;
  obs.side_seen_faces_left = s.seen_faces_left;
  obs.side_seen_confidence = s.seen_confidence;
  obs.side_camera_given = o.side_camera != SideCamera::Auto;
  observe_front(front, bgf, head, front_face, s.profile, row_scale, o, obs);
  for (const auto& p : s.profile.curve) obs.side.boundary.push_back(out_px(p));
  obs.side.boundary_confidence = s.profile.confidence;
  for (const auto& [n, f] : s.profile.features) {
    Feature2d g = f;
    g.px = out_px(f.px);
    obs.side.features[n] = g;
  }
  std::map<std::string, Feature2d> ears;
  add_side_ears(s, obs, ears);
  for (auto& [n, f] : ears) f.px = out_px(f.px), obs.side.features[n] = f;
  add_front_tragi(obs);
  add_side_eye(side, s, obs);
  return obs;
}

FaceObservation observe_front(const cv::Mat& front_in, const ObserveOptions& o) {
  o.check();
  const cv::Mat front = to_bgr8(front_in, "front image");
  check_user_landmarks(o, front);
  const cv::Mat bgf = optional_bgr(o.background_front, front, "front background");
  FaceObservation obs;
  obs.front.width = front.cols, obs.front.height = front.rows;
  const FrontHead head = segment_front(front, bgf);
  obs.front_blob = head.mask;
  observe_front(front, bgf, head, find_front_face(front, o, search_area(head.mask)), SideProfile{},
                1.0, o, obs);
  return obs;
}

bool is_complete(const FaceObservation& obs, std::string* missing) {
  std::string m;
  if (obs.front.boundary.empty()) m += " front-boundary";
  if (obs.side.boundary.empty()) m += " side-profile";
  for (std::string_view n : kLandmarkNames) {
    if (n.find("ear_") == 0) continue;
    const auto it = obs.front.features.find(std::string(n));
    if (it == obs.front.features.end() || it->second.confidence <= 0)
      m += " front:" + std::string(n);
  }
  for (std::string_view n : kProfileLandmarkNames) {
    const auto it = obs.side.features.find(std::string(n));
    if (it == obs.side.features.end() || it->second.confidence <= 0) m += " side:" + std::string(n);
  }
  if (missing) *missing = m.empty() ? "" : m.substr(1);
  return m.empty();
}

}  // namespace orthoface::vision
