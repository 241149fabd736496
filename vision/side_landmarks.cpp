// Profile landmarks from the fitted side-view curve (seed 004 §4: characteristic points of the
// profile; the paper names them, the curve analysis here is ours).
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "vision/curve_features.h"
#include "vision/side_profile.h"

namespace orthoface::vision {

namespace {

Feature2d make(cv::Point2d p, double conf, const char* method) {
  Feature2d f;
  f.px = p;
  f.confidence = conf;
  f.method = method;
  return f;
}

// First / last curve index whose row lies in [y0, y1].
int first_row_at_least(const std::vector<cv::Point2d>& c, double y) {
  for (int i = 0; i < int(c.size()); ++i)
    if (c[i].y >= y) return i;
  return int(c.size()) - 1;
}

int argmin_x(const std::vector<cv::Point2d>& c, int a, int b) {
  int best = a;
  for (int i = a; i <= b; ++i)
    if (c[i].x < c[best].x) best = i;
  return best;
}

// Lab colour (`lab` holds the box starting at `origin`) a few pixels inside the profile (the head
// is to the right of a left-facing curve).
cv::Vec3f inside_colour(const cv::Mat& lab, cv::Point origin, const std::vector<cv::Point2d>& c,
                        int i, double d) {
  const int j0 = std::max(0, i - 2), j1 = std::min(int(c.size()) - 1, i + 2);
  cv::Point2d t = c[j1] - c[j0];
  const double len = std::max(1e-9, cv::norm(t));
  const cv::Point2d in(t.y / len, -t.x / len);  // right-hand normal of a downward walk = inside
  const cv::Point2d p = c[i] + d * (in.x >= 0 ? in : -in) - cv::Point2d(origin);
  const int x = std::clamp(int(std::lround(p.x)), 0, lab.cols - 1);
  const int y = std::clamp(int(std::lround(p.y)), 0, lab.rows - 1);
  return lab.at<cv::Vec3f>(y, x);
}

// Hairline: walking up from `start`, the first place the colour inside the profile leaves the
// forehead skin colour for good. Returns -1 when the colour never changes.
int hairline(const cv::Mat& bgr, const std::vector<cv::Point2d>& c, int start, double h) {
  const double inset = std::max(3.0, 0.02 * h);
  // Lab only inside the box the samples can reach (a whole-image conversion dominated the time).
  cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(c.begin(), c.begin() + start + 1));
  const int pad = int(inset) + 3;
  box = cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad) &
        cv::Rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat f, lab;
  bgr(box).convertTo(f, CV_32F, 1.0 / 255);
  cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
  const int nref = std::max(5, int(0.05 * h));
  cv::Vec3f ref(0, 0, 0);
  int cnt = 0;
  for (int i = start; i > start - nref && i >= 0; --i, ++cnt)
    ref += inside_colour(lab, box.tl(), c, i, inset);
  if (cnt == 0) return -1;
  ref *= 1.0f / cnt;
  int run = 0;
  for (int i = start - nref; i >= 0; --i) {
    const double d = cv::norm(inside_colour(lab, box.tl(), c, i, inset) - ref);
    run = d > 18.0 ? run + 1 : 0;
    if (run >= 4) return i + 3;
  }
  return -1;
}

// Nose tip: the most projecting point of the face band.
int nose_tip_index(const std::vector<cv::Point2d>& c, double H) {
  const double y0 = c.front().y;
  return argmin_x(c, first_row_at_least(c, y0 + 0.35 * H), first_row_at_least(c, y0 + 0.85 * H));
}

// The landmarks' nose tip: near the row the front photo gives when the band there holds a point
// that projects more than both its ends (the band's end itself would be a brow or lip cut off by
// rows that are not shared after all); else nose_tip_index. The face band below the curve's top
// fails where dark hair is lost against the background: the curve then starts at the hairline
// (FRMDB 028, 034), and the band, from 0.35 head heights below it, put the tip on the lips.
int landmark_nose_tip(const std::vector<cv::Point2d>& c, double H, double expected_row) {
  if (expected_row >= 0) {
    const int a = first_row_at_least(c, expected_row - 0.16 * H),
              b = first_row_at_least(c, expected_row + 0.12 * H);
    const int tip = argmin_x(c, a, b);
    if (a < tip && tip < b && c[tip].x < c[a].x - 1 && c[tip].x < c[b].x - 1) return tip;
  }
  return nose_tip_index(c, H);
}

// The curve with the bays above the nose tip (index `tip`) cut out, and the tip's index in it: a
// point of the stretch from the crown to the tip is dropped when another point of that stretch at
// its row lies further forward by more than 0.03 H. A face's front edge has one point a row
// there; a bay is a notch in the head's blob (brown hair lost against a dark curtain at the
// hairline, FRMDB 001, where the nasion was found 100 px inside the hair and the model's forehead
// dented). Below the tip the curve runs back under the chin on purpose and is kept whole.
std::vector<cv::Point2d> without_bays(const std::vector<cv::Point2d>& c, int& tip, double H) {
  double y0 = c[0].y, y1 = c[0].y;
  for (int i = 0; i <= tip; ++i) y0 = std::min(y0, c[i].y), y1 = std::max(y1, c[i].y);
  std::vector<double> front(size_t(std::lround(y1 - y0)) + 1, 1e300);
  const auto row = [&](const cv::Point2d& p) { return size_t(std::lround(p.y - y0)); };
  for (int i = 0; i <= tip; ++i) front[row(c[i])] = std::min(front[row(c[i])], c[i].x);
  std::vector<cv::Point2d> out;
  for (int i = 0; i < tip; ++i)
    if (c[i].x <= front[row(c[i])] + 0.03 * H) out.push_back(c[i]);
  const int kept_tip = int(out.size());
  out.insert(out.end(), c.begin() + tip, c.end());
  tip = kept_tip;
  return out;
}

// The first index below the tip where the curve heads back and keeps going 0.07 H within 0.15 H;
// -1 if none. With `shallow_only` the run must reach its 0.07 H back in less height than it goes
// back.
int backward_run(const std::vector<cv::Point2d>& c, int tip, double H, bool shallow_only) {
  const int n = int(c.size());
  const int lower = std::max(2, first_row_at_least(c, c[tip].y + 0.12 * H));
  const int reach = std::max(4, int(0.15 * H));
  for (int i = lower; i + 2 < n; ++i) {
    const cv::Point2d d = c[i + 2] - c[i - 2];
    if (!(d.x > 0 && std::abs(d.y) < 0.7 * d.x)) continue;
    for (int j = i; j < std::min(n, i + reach); ++j) {
      const double back = c[j].x - c[i].x;
      if (back <= 0.07 * H) continue;
      if (!shallow_only || std::abs(c[j].y - c[i].y) < back) return i;
      break;
    }
  }
  return -1;
}

// Under the chin the curve runs backward a long way (lips only step back a little). A receding
// chin also heads back below the lower lip, but down more than back (FRMDB 020: the chin 30 px
// back over 45 px down, then the dark throat lost against a dark shirt), so a shallow run is
// taken first and a steeper one only when there is none.
int under_chin(const std::vector<cv::Point2d>& c, int tip, double H) {
  const int shallow = backward_run(c, tip, H, true);
  return shallow >= 0 ? shallow : backward_run(c, tip, H, false);
}

// Subnasale: where the columella (running back under the nose) turns down into the upper lip.
// From the most posterior point between the tip and the upper lip, upward to the first point
// whose tangent runs back more than down (45 deg); the deepest point behind the tip-to-lip chord
// lies lower, in the lip's own concavity.
int subnasale_corner(const std::vector<cv::Point2d>& c, int tip, int lu) {
  int deep = tip;
  for (int i = tip; i <= lu; ++i)
    if (c[i].x > c[deep].x) deep = i;
  for (int i = deep; i > tip + 1; --i) {
    const cv::Point2d d = c[i + 1] - c[i - 1];
    if (d.x > std::abs(d.y)) return i;
  }
  return deep;
}

}  // namespace

bool reads_as_face_profile(const std::vector<cv::Point2d>& c, double H) {
  if (c.size() < 40 || H < 20) return false;
  const int tip = nose_tip_index(c, H), under = under_chin(c, tip, H);
  if (under < 0) return false;
  // Between the nose tip and the throat a face steps back (subnasale, the lips' and chin's
  // folds): 9-20 px on the 26 FRMDB profiles (0.03-0.07 H). The back of a skin-only blob (dark
  // hair before a dark background) runs from the nape down the neck without it: 0-3 px.
  double depth = 0;
  deepest_behind_chord(c, tip, under, &depth);
  return depth >= kFaceStepBack * H;
}

void find_profile_landmarks(const cv::Mat& bgr, SideProfile& sp, double expected_nose_row) {
  const auto& c = sp.curve;
  const double H = sp.head_height_px;
  if (c.size() < 40 || H < 20) {
    sp.warnings.push_back("side view: profile too short for landmarks");
    return;
  }
  int tip = landmark_nose_tip(c, H, expected_nose_row);
  sp.curve = without_bays(c, tip, H);
  const int n = int(c.size());
  const double conf = std::clamp(sp.confidence, 0.0, 1.0);
  sp.features["nose_tip"] = make(c[tip], conf, "profile-extremum");
  // Nasion: the deepest point behind the chord from the brow (glabella, the most projecting
  // point of the band above) to the tip; then the most posterior point within a quarter of its
  // height over the tip from it (the soft tissue's own dip, where it has one). The most posterior
  // point of the whole stretch is not it when the head leans forward or the forehead slopes back:
  // on real photos that was the forehead, 50-65 px above the eyes.
  const int g0 = first_row_at_least(c, c[tip].y - 0.42 * H),
            g1 = first_row_at_least(c, c[tip].y - 0.22 * H);
  const int glabella = argmin_x(c, g0, std::max(g0, g1));
  double depth = 0;
  const int chord_deepest = deepest_behind_chord(c, glabella, tip, &depth);
  const double reach = std::max(3.0, 0.25 * (c[tip].y - c[chord_deepest].y));
  int nasion = chord_deepest;
  for (int i = glabella; i < tip; ++i)
    if (std::abs(c[i].y - c[chord_deepest].y) <= reach && c[i].x > c[nasion].x) nasion = i;
  sp.features["nose_bridge"] =
      make(c[nasion], conf * std::min(1.0, depth / 2.0), "profile-concavity");
  const int under = under_chin(c, tip, H);
  if (under < 0) {
    sp.warnings.push_back("side view: chin not found (profile ends before the throat)");
    return;
  }
  // Lips and chin: alternating extrema of the projection between the tip and the under-chin.
  std::vector<double> x;
  for (int i = tip; i <= under; ++i) x.push_back(c[i].x);
  std::vector<int> mins;
  for (const Extremum& e : alternating_extrema(x, 0.6))
    if (!e.is_max && c[tip + e.index].y > c[tip].y + 0.03 * H) mins.push_back(tip + e.index);
  // The chin is the last projecting point before the under-chin; a retruded chin that is no
  // local extremum is taken where the tangent turns vertical above the under-chin.
  int pog = -1;
  if (!mins.empty() && c[mins.back()].y > c[tip].y + 0.2 * H)
    pog = mins.back(), mins.pop_back();
  else
    pog = tangent_closest(c, std::max(tip, under - int(0.12 * H)), under, M_PI / 2);
  sp.features["chin"] = make(c[pog], conf, "profile-extremum");
  const int menton = tangent_closest(c, pog, under, M_PI / 4);  // down-and-back at 45 deg
  sp.features["chin_bottom"] = make(c[menton], conf * 0.8, "profile-tangent");
  if (mins.empty()) {
    // Lips flush with the profile (no extremum): subnasale = deepest point behind the chord in
    // the upper third below the tip, lips = most projecting points near their usual share of
    // the subnasale-to-chin height (position model, low confidence).
    const int sub = deepest_behind_chord(c, tip, tip + (pog - tip) / 3, &depth);
    sp.features["subnasale"] = make(c[sub], conf * 0.4, "profile-concavity");
    const double ys = c[sub].y, span = c[pog].y - ys;
    const auto near_row = [&](double f) {
      const int a = first_row_at_least(c, ys + (f - 0.1) * span);
      return argmin_x(c, a, std::max(a, first_row_at_least(c, ys + (f + 0.1) * span)));
    };
    sp.features["lip_upper"] = make(c[near_row(0.3)], conf * 0.3, "profile-position-model");
    sp.features["lip_lower"] = make(c[near_row(0.62)], conf * 0.3, "profile-position-model");
    sp.warnings.push_back("side view: lips do not stand out on the profile; placed by position");
  } else {
    int lu = mins.front();
    int run_top = lu, run_bottom = lu;  // the flat stretch around the first lip extremum
    while (run_top > tip && c[run_top - 1].x <= c[lu].x + 0.5) --run_top;
    while (run_bottom < pog && c[run_bottom + 1].x <= c[lu].x + 0.5) ++run_bottom;
    // Closed lips projecting equally: one long flat stretch and no notch between them; the
    // upper lip is its top end, the lower lip its bottom end.
    const bool flat_lips = mins.size() < 2 && c[run_bottom].y - c[run_top].y > 0.03 * H;
    if (flat_lips) lu = run_top;
    sp.features["lip_upper"] = flat_lips ? make(c[lu], conf * 0.7, "profile-flat-ends")
                                         : make(c[lu], conf, "profile-extremum");
    deepest_behind_chord(c, tip, lu, &depth);
    const int sub = subnasale_corner(c, tip, lu);
    sp.features["subnasale"] = make(c[sub], conf * std::min(1.0, depth / 1.5), "profile-corner");
    if (mins.size() >= 2) {
      sp.features["lip_lower"] = make(c[mins[1]], conf, "profile-extremum");
    } else if (flat_lips) {
      sp.features["lip_lower"] = make(c[run_bottom], conf * 0.7, "profile-flat-ends");
    } else {
      const int mid = (lu + pog) / 2;  // lower lip not standing out: placed by position
      sp.features["lip_lower"] =
          make(c[argmin_x(c, lu + (pog - lu) / 4, mid)], conf * 0.4, "profile-position-model");
      sp.warnings.push_back("side view: lower lip does not stand out; placed by position");
    }
  }
  const int hl = hairline(bgr, c, glabella, H);
  if (hl >= 0) {
    sp.features["forehead_top"] = make(c[hl], conf * 0.8, "profile-colour");
  } else {
    const int i = first_row_at_least(c, c[nasion].y - 0.3 * H);
    sp.features["forehead_top"] = make(c[i], 0.2, "position-model");
    sp.warnings.push_back("side view: hairline not seen; forehead top placed by position");
  }
  // Trim the curve: throat = a little below the chin bottom.
  const int end = std::min(n - 1, first_row_at_least(c, c[menton].y + 0.12 * H));
  sp.curve.resize(std::max(end + 1, under + 1));
}

}  // namespace orthoface::vision
