#include "vision/pair_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/face_detect.h"
#include "vision/face_landmarks68.h"
#include "vision/image_prep.h"

namespace orthoface::vision {
namespace {

bool known(double v) { return std::isfinite(v); }

std::string fmt(const char* format, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, format, a, b, c);
  return buf;
}

// The inner part of a face box (the detector's box reaches the hairline and the jaw's edge),
// clipped to the image.
cv::Rect inner_box(const cv::Rect2d& box, const cv::Size& size, double keep) {
  const cv::Point2d c = (box.tl() + box.br()) * 0.5;
  const cv::Rect r(cv::Point(int(c.x - keep * box.width / 2), int(c.y - keep * box.height / 2)),
                   cv::Point(int(c.x + keep * box.width / 2), int(c.y + keep * box.height / 2)));
  return r & cv::Rect(cv::Point(0, 0), size);
}

void measure_face_image(const cv::Mat& bgr, const cv::Rect2d& box, PairMeasures& m) {
  const cv::Rect whole = inner_box(box, bgr.size(), 1.0);
  if (whole.width < 8 || whole.height < 8) return;
  cv::Mat grey;
  cv::cvtColor(bgr(whole), grey, cv::COLOR_BGR2GRAY);
  // Blur at one scale whatever the photo's resolution: the face 128 px wide.
  cv::Mat small;
  cv::resize(grey, small,
             cv::Size(128, std::max(8, int(std::lround(128.0 * grey.rows / grey.cols)))), 0, 0,
             grey.cols > 128 ? cv::INTER_AREA : cv::INTER_LINEAR);
  m.front_blur = blur_index(small);
  const cv::Rect in = inner_box(box, bgr.size(), 0.6);
  if (in.width < 4 || in.height < 4) return;
  cv::Mat luma;
  cv::cvtColor(bgr(in), luma, cv::COLOR_BGR2GRAY);
  m.front_luma = cv::mean(luma)[0];
  m.front_clipped = double(cv::countNonZero(luma >= 250)) / luma.total();
}

// Least squares y = a x + b over `p`; false when the x do not spread.
bool fit_line(const std::vector<std::pair<double, double>>& p, double& a, double& b) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(p.size());
  for (const auto& [x, y] : p) sx += x, sy += y, sxx += x * x, sxy += x * y;
  const double den = n * sxx - sx * sx;
  if (!(std::abs(den) > 1e-9)) return false;
  a = (n * sxy - sx * sy) / den, b = (sy - a * sx) / n;
  return true;
}

// Midline heights: the front's trained points (independent of the side photo: the consensus
// points take their rows from the profile) against the side profile's, front = a side + b
// fitted without each point in turn (one may be misplaced); the smallest RMS residual over the
// front's nose-bridge-to-chin height.
double height_residual(const FaceObservation& obs) {
  std::vector<std::pair<double, double>> rows;  // (side row, front row)
  for (const char* n :
       {"nose_bridge", "nose_tip", "subnasale", "lip_upper", "lip_lower", "chin", "chin_bottom"}) {
    const Feature2d* f = find_feature(obs.front_trained, n);
    const Feature2d* s = find_feature(obs.side.features, n);
    if (f && s && s->confidence > 0) rows.emplace_back(s->px.y, f->px.y);
  }
  const Feature2d* top = find_feature(obs.front_trained, "nose_bridge");
  const Feature2d* bottom = find_feature(obs.front_trained, "chin_bottom");
  if (rows.size() < 5 || !top || !bottom || bottom->px.y <= top->px.y) return PairMeasures::kNaN;
  double best = PairMeasures::kNaN;
  for (size_t drop = 0; drop < rows.size(); ++drop) {
    std::vector<std::pair<double, double>> kept = rows;
    kept.erase(kept.begin() + long(drop));
    double a, b;
    if (!fit_line(kept, a, b)) continue;
    double ss = 0;
    for (const auto& [x, y] : kept) ss += (a * x + b - y) * (a * x + b - y);
    const double rms = std::sqrt(ss / kept.size());
    if (!(rms >= best)) best = rms;
  }
  return best / (bottom->px.y - top->px.y);
}

// Median CIE L*a*b* colour of a square patch (centre, half size) of `bgr`; none when the patch
// leaves the image.
std::optional<cv::Vec3d> patch_lab(const cv::Mat& bgr, cv::Point2d centre, double half) {
  const cv::Rect r(cv::Point(int(centre.x - half), int(centre.y - half)),
                   cv::Point(int(centre.x + half) + 1, int(centre.y + half) + 1));
  if (half < 1 || (r & cv::Rect(cv::Point(0, 0), bgr.size())) != r) return std::nullopt;
  cv::Mat lab;
  cv::Mat f;
  bgr(r).convertTo(f, CV_32F, 1.0 / 255);
  cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
  cv::Vec3d out;
  std::vector<float> v(lab.total());
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < v.size(); ++i)
      v[i] = lab.at<cv::Vec3f>(int(i / lab.cols), int(i % lab.cols))[c];
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    out[c] = v[v.size() / 2];
  }
  return out;
}

// Cheek skin: in the front photo below each eye, halfway to the nose tip's row; in the side
// photo under the eye, behind the nose tip by 1.2 nose lengths (nasion to tip).
double skin_delta_e(const cv::Mat& front, const cv::Mat& side, const FaceObservation& obs) {
  const Feature2d* el = find_feature(obs.front_trained, "eye_left_center");
  const Feature2d* er = find_feature(obs.front_trained, "eye_right_center");
  const Feature2d* tip = find_feature(obs.front_trained, "nose_tip");
  const Feature2d* s_tip = find_feature(obs.side.features, "nose_tip");
  const Feature2d* s_bridge = find_feature(obs.side.features, "nose_bridge");
  if (!el || !er || !tip || !s_tip || !s_bridge) return PairMeasures::kNaN;
  const double eyes = cv::norm(el->px - er->px);
  std::vector<cv::Vec3d> fronts;
  for (const Feature2d* e : {el, er}) {
    const cv::Point2d c(e->px.x - 0.5, 0.5 * (e->px.y + tip->px.y) - 0.5);
    if (auto lab = patch_lab(front, c, 0.1 * eyes)) fronts.push_back(*lab);
  }
  const double nose = s_tip->px.y - s_bridge->px.y;
  if (fronts.empty() || nose <= 0) return PairMeasures::kNaN;
  const double behind = obs.side_faces_left ? 1.0 : -1.0;
  const cv::Point2d c(s_tip->px.x + behind * 1.2 * nose - 0.5, s_bridge->px.y + 0.6 * nose - 0.5);
  const auto side_lab = patch_lab(side, c, 0.2 * nose);
  if (!side_lab) return PairMeasures::kNaN;
  double best = 1e300;
  for (const cv::Vec3d& f : fronts) best = std::min(best, cv::norm(f - *side_lab));
  return best;
}

// CIE a* x b* histogram (normalised) of the subject's blob (observation.front_blob /
// side_blob) above `bottom_row`: hair, skin and clothes, without the lightness the two views are
// lit with differently. Empty when there is no blob.
cv::Mat subject_histogram(const cv::Mat& bgr, const cv::Mat& blob, double bottom_row) {
  if (blob.size() != bgr.size()) return {};
  cv::Mat mask = blob.clone();
  if (bottom_row < mask.rows) mask.rowRange(std::max(0, int(bottom_row)), mask.rows).setTo(0);
  if (cv::countNonZero(mask) == 0) return {};
  cv::Mat lab, hist;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  const int channels[] = {1, 2}, bins[] = {32, 32};
  const float a[] = {64, 192}, b[] = {64, 192};  // 8-bit a*, b* (128 = neutral)
  const float* ranges[] = {a, b};
  cv::calcHist(&lab, 1, channels, mask, hist, 2, bins, ranges);
  cv::normalize(hist, hist, 1, 0, cv::NORM_L1);
  return hist;
}

// The subject's colours down to the chin plus 1.5 nose-bridge-to-chin heights (neck and
// collar) in both photos; NaN without the chin and nose bridge in both, or without the blobs.
double colour_distance(const cv::Mat& front, const cv::Mat& side, const FaceObservation& obs) {
  const Feature2d* fc = find_feature(obs.front_trained, "chin_bottom");
  const Feature2d* fn = find_feature(obs.front_trained, "nose_bridge");
  const Feature2d* sc = find_feature(obs.side.features, "chin_bottom");
  const Feature2d* sn = find_feature(obs.side.features, "nose_bridge");
  if (!fc || !fn || !sc || !sn) return PairMeasures::kNaN;
  const cv::Mat hf =
      subject_histogram(front, obs.front_blob, fc->px.y + 1.5 * (fc->px.y - fn->px.y));
  const cv::Mat hs = subject_histogram(side, obs.side_blob, sc->px.y + 1.5 * (sc->px.y - sn->px.y));
  if (hf.empty() || hs.empty()) return PairMeasures::kNaN;
  return cv::compareHist(hf, hs, cv::HISTCMP_BHATTACHARYYA);
}

InputCheck make(const char* name, bool passed, double value, double limit, std::string problem) {
  InputCheck c;
  c.name = name;
  c.passed = passed;
  c.value = value;
  c.limit = limit;
  if (!passed) c.problem = std::move(problem);
  return c;
}

// A check that passes when `value` is unknown (another check names what is missing) or at most
// `limit`.
InputCheck at_most(const char* name, double value, double limit, std::string problem) {
  return make(name, !known(value) || value <= limit, value, limit, std::move(problem));
}

}  // namespace

double blur_index(const cv::Mat& grey) {
  if (grey.empty() || grey.type() != CV_8UC1)
    throw std::invalid_argument("blur index: expected a non-empty 8-bit grey image");
  cv::Mat f;
  grey.convertTo(f, CV_32F);
  double worst = 0;
  for (int dir = 0; dir < 2; ++dir) {  // 0: along columns (vertical), 1: along rows
    cv::Mat b;
    cv::blur(f, b, dir == 0 ? cv::Size(1, 9) : cv::Size(9, 1), cv::Point(-1, -1),
             cv::BORDER_REFLECT);
    const cv::Mat kernel =
        dir == 0 ? (cv::Mat_<float>(2, 1) << -1, 1) : (cv::Mat_<float>(1, 2) << -1, 1);
    cv::Mat df, db;
    cv::filter2D(f, df, CV_32F, kernel, cv::Point(0, 0));
    cv::filter2D(b, db, CV_32F, kernel, cv::Point(0, 0));
    df = cv::abs(df), db = cv::abs(db);
    cv::Mat v = cv::max(df - db, 0.0);
    const double s_f = cv::sum(df)[0], s_v = cv::sum(v)[0];
    worst = std::max(worst, s_f > 0 ? (s_f - s_v) / s_f : 1.0);
  }
  return worst;
}

PairMeasures measure_pair(const cv::Mat& front_in, const cv::Mat& side_in,
                          const FaceObservation& obs) {
  if (front_in.empty() || side_in.empty())
    throw std::invalid_argument("input check: the front or side photo is empty");
  const cv::Mat front = to_bgr8(front_in, "front photo"), side = to_bgr8(side_in, "side photo");
  if (front.cols != obs.front.width || front.rows != obs.front.height ||
      side.cols != obs.side.width || side.rows != obs.side.height)
    throw std::invalid_argument("input check: the photos are not the ones observed");
  PairMeasures m;
  m.front = find_face(front);
  if (m.front.faces > 0) measure_face_image(front, m.front.box, m);
  m.side = obs.side_face;
  if (m.side.faces > 0 && known(m.side.turn)) {
    const double front_rad = known(m.front.turn) ? std::atan(m.front.turn / kTurnPerTan) : 0.0;
    m.side_angle_deg = std::abs(std::atan(m.side.turn / kTurnPerTan) - front_rad) * 180.0 / M_PI;
  }
  m.height_residual = height_residual(obs);
  m.skin_delta_e = skin_delta_e(front, side, obs);
  m.colour_distance = colour_distance(front, side, obs);
  // A face found in the side photo whose nose points the way --side-camera says (turn index < 0:
  // toward the image left) outvotes vision's silhouette cues (hair as dark as the background
  // leaves them a skin-only blob to judge).
  const bool face_agrees = known(m.side.turn) && (m.side.turn < 0) == obs.side_faces_left;
  if (obs.side_camera_given && obs.side_seen_faces_left != obs.side_faces_left && !face_agrees)
    m.side_facing_against = obs.side_seen_confidence;
  return m;
}

void PairCheckLimits::check() const {
  for (double v : {sure_face_score, max_front_turn, min_side_angle_deg, min_face_px, max_blur,
                   max_clipped, min_luma, max_facing_against, max_height_residual, max_skin_delta_e,
                   max_colour_distance, max_face_distance})
    if (!(v > 0) || !std::isfinite(v))
      throw std::invalid_argument("input check: every limit must be positive and finite");
}

bool PairCheck::passed() const {
  return std::all_of(checks.begin(), checks.end(), [](const InputCheck& c) { return c.passed; });
}

std::string PairCheck::first_failure() const {
  for (const auto& c : checks)
    if (!c.passed) return c.name + ": " + c.problem;
  return {};
}

PairCheck check_pair(const PairMeasures& m, const PairCheckLimits& lim) {
  lim.check();
  PairCheck out;
  out.measures = m;
  auto& c = out.checks;
  const bool front_sure = m.front.faces > 0 && m.front.score >= lim.sure_face_score;
  const bool side_sure = m.side.faces > 0 && m.side.score >= lim.sure_face_score;
  const bool side_frontal =
      side_sure && known(m.side.turn) && std::abs(m.side.turn) <= lim.max_front_turn;
  const bool front_frontal =
      front_sure && !(known(m.front.turn) && std::abs(m.front.turn) > lim.max_front_turn);
  c.push_back(make("swapped", !(side_frontal && !front_frontal), m.side.turn, lim.max_front_turn,
                   "the front photo shows no frontal face and the side photo does: front and "
                   "side are swapped"));
  c.push_back(make(
      "front_face", m.front.faces == 1 && front_sure, m.front.faces, 1,
      m.front.faces == 0 ? "no face found in the front photo"
      : m.front.faces > 1
          ? std::to_string(m.front.faces) + " faces in the front photo; it must show one person"
          : fmt("the front photo's face is not clearly a face seen from the front "
                "(detector score %.2f, limit %.2f)",
                m.front.score, lim.sure_face_score)));
  const bool face = m.front.faces > 0;
  c.push_back(make("face_size", !face || m.front.box.width >= lim.min_face_px, m.front.box.width,
                   lim.min_face_px,
                   fmt("the face in the front photo is %.0f px wide; at least %.0f px are needed",
                       m.front.box.width, lim.min_face_px)));
  c.push_back(at_most("sharpness", m.front_blur, lim.max_blur,
                      fmt("the front photo's face is blurred (blur index %.2f, limit %.2f)",
                          m.front_blur, lim.max_blur)));
  const bool clipped = known(m.front_clipped) && m.front_clipped > lim.max_clipped;
  const bool dark = known(m.front_luma) && m.front_luma < lim.min_luma;
  c.push_back(make("exposure", !clipped && !dark, clipped ? m.front_clipped : m.front_luma,
                   clipped ? lim.max_clipped : lim.min_luma,
                   clipped ? fmt("the front photo's face is over-exposed (%.0f %% of it white, "
                                 "limit %.0f %%)",
                                 100 * m.front_clipped, 100 * lim.max_clipped)
                           : fmt("the front photo's face is too dark (mean luminance %.0f, "
                                 "limit %.0f)",
                                 m.front_luma, lim.min_luma)));
  c.push_back(make("front_frontal",
                   !known(m.front.turn) || std::abs(m.front.turn) <= lim.max_front_turn,
                   m.front.turn, lim.max_front_turn,
                   fmt("the head is turned in the front photo (turn index %.2f, about %.0f "
                       "degrees; limit %.2f)",
                       m.front.turn, std::atan(std::abs(m.front.turn) / kTurnPerTan) * 180 / M_PI,
                       lim.max_front_turn)));
  const bool side_ok =
      !side_sure || !known(m.side_angle_deg) || m.side_angle_deg >= lim.min_side_angle_deg;
  c.push_back(make("side_profile", side_ok, m.side_angle_deg, lim.min_side_angle_deg,
                   fmt("the side photo is not a profile: it sees the face %.0f degrees from the "
                       "front photo (at least %.0f needed)",
                       m.side_angle_deg, lim.min_side_angle_deg)));
  c.push_back(make("side_camera", m.side_facing_against <= lim.max_facing_against,
                   m.side_facing_against, lim.max_facing_against,
                   fmt("the profile looks the other way than --side-camera says (confidence "
                       "%.2f, limit %.2f)",
                       m.side_facing_against, lim.max_facing_against)));
  c.push_back(at_most("same_person_heights", m.height_residual, lim.max_height_residual,
                      fmt("nose, lips and chin sit at other proportions in the two photos "
                          "(%.3f of the face height, limit %.3f): two different people?",
                          m.height_residual, lim.max_height_residual)));
  c.push_back(at_most("same_person_skin", m.skin_delta_e, lim.max_skin_delta_e,
                      fmt("the cheeks differ in colour between the two photos (delta E %.1f, "
                          "limit %.1f): two different people?",
                          m.skin_delta_e, lim.max_skin_delta_e)));
  c.push_back(at_most("same_person_colours", m.colour_distance, lim.max_colour_distance,
                      fmt("hair, skin and collar differ in colour between the two photos "
                          "(distance %.2f, limit %.2f): two different people?",
                          m.colour_distance, lim.max_colour_distance)));
  return out;
}

}  // namespace orthoface::vision
