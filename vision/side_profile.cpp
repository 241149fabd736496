#include "vision/side_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "vision/contour_chain.h"
#include "vision/curve_features.h"
#include "vision/edges.h"
#include "vision/foreground.h"

namespace orthoface::vision {

void SideProfileOptions::check() const {
  if (!(control_spacing_px >= 3 && control_spacing_px <= 100))
    throw std::invalid_argument("SideProfileOptions: control_spacing_px must be in [3, 100]");
  if (!(min_head_height_px >= 0))
    throw std::invalid_argument("SideProfileOptions: min_head_height_px must be >= 0");
  if (!std::isfinite(expected_nose_row))
    throw std::invalid_argument("SideProfileOptions: expected_nose_row is not finite");
  fit.check();
}

namespace {

// Crown-to-chin height from the blob: a head is about 1.2x as tall as it is deep (front-back),
// and its depth is reached within about 0.9 depth below the crown. A blob that lost the hair
// (hair as dark as the background) is narrower: `at_least` (e.g. the front view's head width)
// bounds the estimate from below.
double head_height_estimate(const RowExtent& e, double at_least) {
  return std::max(1.2 * head_width(e), at_least);
}

// A contour chain at ~1 px steps (empty stays empty).
std::vector<cv::Point2d> resample_chain(const std::vector<cv::Point2d>& chain) {
  return chain.size() < 2 ? chain : resample(chain, 1.0);
}

// Refined dense profile: mask chain -> B-spline -> iterative fit on the probability edges.
std::vector<cv::Point2d> fitted_curve(const std::vector<cv::Point2d>& chain, const cv::Mat& prob,
                                      const SideProfileOptions& o, double* support) {
  const std::vector<cv::Point2d> pts = resample(chain, 2.0);
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += cv::norm(pts[i] - pts[i - 1]);
  const int nc = std::clamp(int(len / o.control_spacing_px), 6, 150);
  BSpline2d init = fit_bspline(pts, chord_parameters(pts), {}, nc, 0.05);
  ProfileFitOptions f = o.fit;
  f.num_control = nc;
  f.samples = std::max(nc * 4, int(len / 1.5));
  f.polarity = -1;  // the probability falls toward the left-hand normal (outside)
  f.search_px = 4.0;
  f.min_search_px = 1.5;
  f.iterations = 3;
  f.smoothness = 0.02;
  // Edges near the chain only: its box plus the fit's search range and the filters' support.
  const int pad = 12;
  const cv::Rect box = cv::boundingRect(std::vector<cv::Point2f>(chain.begin(), chain.end()));
  const EdgeImage edges =
      edge_image(prob, {0.7, 0.1},
                 cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad));
  const ProfileFit fit = fit_profile_to_edges(init, edges, f);
  *support = fit.support;
  return resample(bspline_samples(fit.spline, std::max(50, int(len))), 1.0);
}

// The probability's smoothing widens the blob by about a pixel: each curve point goes along the
// curve's normal to the photo's own colour step nearby, and a landmark on the curve moves with
// its nearest curve point (landmarks are found on the smooth fit, whose extrema the per-point
// steps would only add noise to).
void on_colour_step(const cv::Mat& bgr, SideProfile& sp) {
  const std::vector<cv::Point2d>& c = sp.curve;
  if (c.size() < 3) return;
  std::vector<cv::Point2d> normals(c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    const cv::Point2d t = c[std::min(i + 2, c.size() - 1)] - c[i < 2 ? 0 : i - 2];
    normals[i] = cv::norm(t) > 1e-9 ? cv::Point2d(-t.y, t.x) : cv::Point2d(1.0, 0.0);
  }
  const std::vector<cv::Point2d> snapped = snap_to_colour_step(bgr, c, normals);
  for (auto& [name, f] : sp.features) {
    size_t best = 0;
    for (size_t i = 1; i < c.size(); ++i)
      if (cv::norm(c[i] - f.px) < cv::norm(c[best] - f.px)) best = i;
    if (cv::norm(c[best] - f.px) <= 1.5) f.px += snapped[best] - c[best];
  }
  sp.curve = snapped;
}

}  // namespace

bool profile_faces_left(const cv::Mat& mask, double* confidence) {
  return profile_faces_left(mask, cv::Mat(), confidence, 0.0);
}

// Lit skin stands on the face side of the head and (darker) hair at the back: mean offset, in
// units of 0.1 x head depth, of the columns of skin-coloured pixels brighter than the blob's
// median from the columns of all blob pixels over the head rows; positive when that skin lies
// left of the blob middle. 0 when too little such skin is seen (e.g. fair hair, bald heads).
double skin_offset(const cv::Mat& mask, const cv::Mat& bgr, const RowExtent& e, double h) {
  const int r0 = std::max(0, e.top), r1 = std::min(e.bottom, int(e.top + 0.8 * h));
  if (r1 <= r0) return 0;
  int c0 = mask.cols, c1 = -1;  // columns the blob spans over these rows
  for (int r = r0; r <= r1; ++r)
    if (e.left[r] >= 0) c0 = std::min(c0, e.left[r]), c1 = std::max(c1, e.right[r]);
  if (c1 < c0) return 0;
  // Every other row and column is enough for two centroids (a quarter of the work).
  std::vector<int> hist(256, 0);
  double mx = 0, mn = 0, depth = 0;
  for (int r = r0; r <= r1; ++r)
    if (e.left[r] >= 0) depth = std::max(depth, double(e.right[r] - e.left[r]));
  struct Sample {
    int c;
    uchar luma;
    float skin;
  };
  std::vector<Sample> samples;
  for (int r = r0; r <= r1; r += 2) {
    const uchar* m = mask.ptr<uchar>(r);
    const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(r);
    for (int c = std::max(0, e.left[r]); e.left[r] >= 0 && c <= e.right[r]; c += 2) {
      if (!m[c]) continue;
      const YCrCb y = to_ycrcb(p[c]);
      samples.push_back({c, y.luma, skin_likelihood(y)});
      mx += c, ++mn, ++hist[y.luma];
    }
  }
  int med = 0;
  for (double acc = 0; med < 255 && (acc += hist[med]) < mn / 2;) ++med;
  double sx = 0, sn = 0;
  for (const Sample& q : samples)
    if (q.skin > 0.5f && q.luma > med + 10) sx += q.c, ++sn;
  if (sn < 0.05 * mn || depth < 10) return 0;
  return (mx / mn - sx / sn) / (0.1 * depth);
}

// The face side of a profile shows lit skin right at the blob's edge over the face rows
// (forehead, nose, lips, chin); the back shows hair there (brown hair passes the YCrCb skin box,
// but it is darker). Mean skin likelihood x luma of a few pixels inside the left edge over the
// rows [top + 0.3 h, top + 0.8 h], minus the same on the right, over the larger of the two:
// > 0 when the left edge is the lit skin.
double edge_skin(const cv::Mat& bgr, const RowExtent& e, double h) {
  const int r0 = std::max(0, int(e.top + 0.3 * h)), r1 = std::min(e.bottom, int(e.top + 0.8 * h));
  const int inset = std::max(2, int(0.01 * h)), span = std::max(3, int(0.02 * h));
  int n = 0;
  double left = 0, right = 0;
  const auto lit_skin = [&](int r, int c0, int dir) {
    double s = 0;
    for (int d = inset; d < inset + span; ++d) {
      const YCrCb y = to_ycrcb(bgr.at<cv::Vec3b>(r, std::clamp(c0 + dir * d, 0, bgr.cols - 1)));
      s += skin_likelihood(y) * y.luma;
    }
    return s / span;
  };
  for (int r = r0; r <= r1; r += 2) {
    if (e.left[r] < 0 || e.right[r] - e.left[r] < 2 * (inset + span)) continue;
    ++n;
    left += lit_skin(r, e.left[r], 1);
    right += lit_skin(r, e.right[r], -1);
  }
  return n < 5 || left + right <= 0 ? 0.0 : (left - right) / std::max(left, right);
}

// +1 when only the blob's left side reads as a face profile, -1 when only its right side does,
// 0 when both or neither (the other cues decide).
double face_profile_side(const cv::Mat& mask, const RowExtent& e, double h) {
  const int stop = std::min(e.bottom, int(e.top + 1.45 * h));
  cv::Mat flipped;  // the blob's box, mirrored: the right side becomes a left-facing front
  cv::flip(mask(cv::boundingRect(mask)), flipped, 1);
  const int shift = cv::boundingRect(mask).y;
  const bool left = reads_as_face_profile(resample_chain(front_chain(mask, stop)), h);
  const bool right = reads_as_face_profile(resample_chain(front_chain(flipped, stop - shift)), h);
  return double(left) - double(right);
}

bool profile_faces_left(const cv::Mat& mask, const cv::Mat& bgr, double* confidence,
                        double min_head_height_px) {
  if (!(min_head_height_px >= 0))
    throw std::invalid_argument("profile_faces_left: min_head_height_px must be >= 0");
  if (!bgr.empty() && (bgr.size() != mask.size() || bgr.type() != CV_8UC3))
    throw std::invalid_argument("profile_faces_left: image and mask differ in size/type");
  const RowExtent e = row_extent(mask);
  if (confidence) *confidence = 0;
  if (e.top < 0) return true;
  const double h = head_height_estimate(e, min_head_height_px);
  // Cues: the nose bump sticks out on the face side; the neck stands behind the face (only
  // when those rows are narrower than the head: wider, they are the torso); skin lies on
  // the face side of the hair; lit skin lines the face-side edge.
  const cv::Point2d p = side_protrusions(e, int(e.top + 0.3 * h), int(e.top + 0.85 * h));
  const double bump = (p.x - p.y) / std::max(4.0, 0.04 * h);
  double neck = 0, neck_w = 0, head_w = 0;
  int nr = 0;
  for (int r = int(e.top + 1.0 * h); r <= std::min(e.bottom, int(e.top + 1.15 * h)); ++r)
    if (r >= 0 && e.left[r] >= 0) neck_w += e.right[r] - e.left[r], ++nr;
  for (int r = e.top; r <= std::min(e.bottom, int(e.top + 0.8 * h)); ++r)
    if (e.left[r] >= 0) head_w = std::max(head_w, double(e.right[r] - e.left[r]));
  if (nr > 0 && neck_w / nr < head_w) neck = neck_offset(e, h) / std::max(4.0, 0.05 * h);
  const double skin = bgr.empty() ? 0.0 : skin_offset(mask, bgr, e, h);
  const double edge = bgr.empty() ? 0.0 : edge_skin(bgr, e, h);
  // The strongest cue: only the face side of the blob reads as a profile with a chin (hair as
  // dark as the background leaves a skin-only blob whose back edge the other cues misjudge).
  const double shape = face_profile_side(mask, e, h);
  const double vote = std::clamp(bump, -2.0, 2.0) + 2.0 * std::clamp(neck, -2.0, 2.0) +
                      3.0 * std::clamp(skin, -2.0, 2.0) + 2.0 * std::clamp(edge / 0.2, -2.0, 2.0) +
                      12.0 * shape;
  if (confidence) *confidence = std::clamp(std::abs(vote) / 2.0, 0.0, 1.0);
  return vote >= 0;
}

SideProfile side_profile(const cv::Mat& bgr, const cv::Mat& prob, const cv::Mat& mask,
                         const SideProfileOptions& o) {
  o.check();
  if (bgr.type() != CV_8UC3 || prob.type() != CV_32F || mask.type() != CV_8U ||
      bgr.size() != prob.size() || bgr.size() != mask.size())
    throw std::invalid_argument("side_profile: image, probability and mask differ in size/type");
  SideProfile sp;
  const RowExtent e = row_extent(mask);
  if (e.top < 0) {
    sp.warnings.push_back("side view: no head found");
    return sp;
  }
  sp.head_height_px = head_height_estimate(e, o.min_head_height_px);
  const int stop = std::min(e.bottom, int(e.top + 1.45 * sp.head_height_px));
  const std::vector<cv::Point2d> chain = front_chain(mask, stop);
  if (chain.size() < 40) {
    sp.warnings.push_back("side view: head blob too small for a profile");
    return sp;
  }
  double support = 0;
  sp.curve = fitted_curve(chain, prob, o, &support);
  sp.confidence = support;
  // On the smooth fitted curve: extrema and concavities.
  find_profile_landmarks(bgr, sp, o.expected_nose_row);
  on_colour_step(bgr, sp);
  if (e.top == 0) sp.warnings.push_back("side view: head touches the top border (crown cut off)");
  if (e.left[std::clamp(int(e.top + 0.6 * sp.head_height_px), 0, mask.rows - 1)] == 0)
    sp.warnings.push_back("side view: face touches the image border (profile cut off)");
  return sp;
}

}  // namespace orthoface::vision
