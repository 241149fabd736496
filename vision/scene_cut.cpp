#include "vision/scene_cut.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "vision/contour_chain.h"
#include "vision/edges.h"
#include "vision/foreground.h"

namespace orthoface::vision {

namespace {

constexpr int kGrabCutIterations = 5;
constexpr double kWorkWidth = 240;  // columns GrabCut works on

void require_bgr(const cv::Mat& m, const char* what) {
  if (m.empty() || m.type() != CV_8UC3)
    throw std::invalid_argument(std::string(what) + ": expected a non-empty 8-bit BGR image");
}

void require_face(const cv::Rect2d& face, cv::Size size, const char* what) {
  if (!(face.width > 1 && face.height > 1) ||
      (cv::Rect2d(0, 0, size.width, size.height) & face).area() <= 0)
    throw std::invalid_argument(std::string(what) + ": the face box is empty or off the photo");
}

// Sets the part of `rect` inside the trimap to `label`.
void fill(cv::Mat& trimap, const cv::Rect2d& rect, int label) {
  const cv::Rect r = cv::Rect(cv::Point(int(std::floor(rect.x)), int(std::floor(rect.y))),
                              cv::Point(int(std::ceil(rect.br().x)), int(std::ceil(rect.br().y)))) &
                     cv::Rect(0, 0, trimap.cols, trimap.rows);
  if (r.area() > 0) trimap(r).setTo(label);
}

void fill_ellipse(cv::Mat& trimap, cv::Point2d centre, cv::Size2d axes, int label) {
  cv::ellipse(trimap, cv::Point(cvRound(centre.x), cvRound(centre.y)),
              cv::Size(std::max(1, cvRound(axes.width)), std::max(1, cvRound(axes.height))), 0, 0,
              360, cv::Scalar(label), cv::FILLED);
}

// Where the border colours say background, a probable subject starts as probable background:
// GrabCut's subject colours then start from the subject, not from the sky or the wall around it.
void border_prior(cv::Mat& trimap, const cv::Mat& border) {
  if (border.empty()) return;
  if (border.size() != trimap.size() || border.type() != CV_32F)
    throw std::invalid_argument("scene cut: the border probability is not the photo's size");
  trimap.setTo(cv::GC_PR_BGD, (trimap == cv::GC_PR_FGD) & (border < 0.5f));
}

// GrabCut's outline lies where its colour models change their minds, up to a few pixels off the
// photo's own edge: each outline point moves along the outline's normal to the strongest colour
// step within kCutSnapPx (vision/edges.h). In fillPoly's fixed point (kSubPixelBits).
constexpr double kCutSnapPx = 5.0;
constexpr int kSubPixelBits = 3;
// drop_foreign_colours: the least share of the head core's pixels a colour (with its neighbouring
// bins) must hold to be the head's.
constexpr double kForeignShare = 0.002;

// The cut's probability: its mask smoothed by a 5x5 Gaussian (sigma 1 px).
void smooth_probability(SceneCut& cut) {
  cut.mask.convertTo(cut.probability, CV_32F, 1.0 / 255);
  cv::GaussianBlur(cut.probability, cut.probability, cv::Size(5, 5), 1.0);
}

// The outer outline of `mask`'s part that holds `seed`; empty when no part does.
std::vector<cv::Point> outline_holding(const cv::Mat& mask, cv::Point seed) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  for (auto& contour : contours)
    if (cv::pointPolygonTest(contour, cv::Point2f(seed), false) >= 0) return std::move(contour);
  return {};
}
std::vector<cv::Point> on_colour_steps(const cv::Mat& bgr, const std::vector<cv::Point>& outline) {
  const int n = int(outline.size()), k = 3;
  std::vector<cv::Point2d> points(n), normals(n);
  for (int i = 0; i < n; ++i) {
    const cv::Point2d t = cv::Point2d(outline[(i + k) % n] - outline[(i - k + n) % n]);
    points[i] = cv::Point2d(outline[i]);
    normals[i] = cv::norm(t) > 0 ? cv::Point2d(t.y, -t.x) / cv::norm(t) : cv::Point2d(1, 0);
  }
  const std::vector<cv::Point2d> moved = snap_to_colour_step(bgr, points, normals, kCutSnapPx);
  std::vector<cv::Point> fixed(n);
  for (int i = 0; i < n; ++i)
    fixed[i] = cv::Point(cvRound(moved[i].x * (1 << kSubPixelBits)),
                         cvRound(moved[i].y * (1 << kSubPixelBits)));
  return fixed;
}

// GrabCut on the part of the photo inside `roi`, from the trimap's labels (the pixels outside stay
// background); the blob holding `seed`, holes filled. `open_px`: the width of the thinnest part
// kept (cables, frames, lines across the subject's edge join the scene to it otherwise).
SceneCut grab_cut(const cv::Mat& bgr, const cv::Mat& trimap, const cv::Rect2d& roi_d,
                  cv::Point seed, int open_px) {
  const cv::Rect roi = cv::Rect(cv::Point(int(roi_d.x), int(roi_d.y)),
                                cv::Point(int(roi_d.br().x), int(roi_d.br().y))) &
                       cv::Rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat labels = trimap(roi).clone();
  SceneCut cut;
  const int subject = cv::countNonZero(labels & 1);      // GC_FGD and GC_PR_FGD are the odd labels
  if (subject == 0 || subject == int(labels.total())) {  // GrabCut needs both to start from
    cut.probability = cv::Mat::zeros(bgr.size(), CV_32F);
    return cut;
  }
  // GrabCut seeds its colour models by k-means from the thread's random generator: a fixed seed
  // makes the cut the same whatever ran on the thread before (the caller's generator is kept).
  const cv::RNG callers = cv::theRNG();
  cv::theRNG().state = 0x5eedc07ull;
  // GrabCut's graph cuts cost about 0.5 s an iteration on a 640x480 region: it runs on the region
  // reduced to kWorkWidth columns, and the outline comes back to the photo's own edges below.
  const double scale = std::min(1.0, kWorkWidth / roi.width);
  cv::Mat work = bgr(roi), work_labels = labels;
  if (scale < 1.0) {
    cv::resize(bgr(roi), work, cv::Size(), scale, scale, cv::INTER_AREA);
    cv::resize(labels, work_labels, work.size(), 0, 0, cv::INTER_NEAREST);
  }
  cv::Mat bgd, fgd;
  cv::grabCut(work, work_labels, cv::Rect(), bgd, fgd, kGrabCutIterations, cv::GC_INIT_WITH_MASK);
  cv::theRNG() = callers;
  if (scale < 1.0)
    cv::resize(work_labels, labels, labels.size(), 0, 0, cv::INTER_NEAREST);
  else
    labels = work_labels;
  cv::Mat fg = cv::Mat::zeros(bgr.size(), CV_8U);
  cv::Mat sub = fg(roi);
  cv::compare(labels & 1, 0, sub, cv::CMP_GT);
  const int k_px = std::max(5, open_px | 1);
  cv::morphologyEx(fg, fg, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k_px, k_px)));
  cv::morphologyEx(fg, fg, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  const std::vector<cv::Point> held = outline_holding(fg, seed);
  if (held.empty()) {
    cut.probability = cv::Mat::zeros(bgr.size(), CV_32F);
    return cut;
  }
  cut.mask = cv::Mat::zeros(bgr.size(), CV_8U);
  const std::vector<cv::Point> outline = on_colour_steps(bgr, held);
  cv::fillPoly(cut.mask, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255), cv::LINE_8,
               kSubPixelBits);
  smooth_probability(cut);
  return cut;
}

// A front view's head is about symmetric about the face's centre column `cx`: on the rows above
// `last_row`, a side reaching more than 1.15 times as far from it as the other side, plus
// `slack_px`, holds the scene (a lamp, a shelf edge the cut joined to the ear or the hair) and
// is clipped there; the blob is then smoothed again.
void clip_to_symmetry(SceneCut& cut, double cx, int last_row, double slack_px) {
  if (cut.mask.empty()) return;
  const RowExtent e = row_extent(cut.mask);
  bool clipped = false;
  for (int r = std::max(0, e.top); r <= std::min(last_row, e.bottom); ++r) {
    if (e.left[r] < 0) continue;
    const double left = cx - e.left[r], right = e.right[r] + 1 - cx;
    if (left <= 0 || right <= 0) continue;
    uchar* m = cut.mask.ptr<uchar>(r);
    if (left > 1.15 * right + slack_px) {
      std::fill(m, m + std::max(0, int(std::ceil(cx - 1.15 * right - slack_px))), uchar(0));
      clipped = true;
    } else if (right > 1.15 * left + slack_px) {
      std::fill(m + std::min(cut.mask.cols, int(cx + 1.15 * left + slack_px)), m + cut.mask.cols,
                uchar(0));
      clipped = true;
    }
  }
  if (clipped) smooth_probability(cut);
}

// Scene objects that touch the head (a toy at the temple, a disc on the crown) join the cut
// when GrabCut's scene colours lack theirs. Above `last_row` the cut's pixels whose colour the
// head's sure core (trimap GC_FGD: the inner face, the hair or scalp above the brows) never
// shows, within one colour bin either way, are dropped; the part holding `seed` is kept, its
// holes filled. Rows from `last_row` down (neck, clothes) stay as cut.
void drop_foreign_colours(const cv::Mat& bgr, const cv::Mat& trimap, int last_row, cv::Point seed,
                          SceneCut& cut) {
  if (cut.mask.empty()) return;
  std::vector<float> core(kColourBins, 0.f);
  double n = 0;
  for (int r = 0; r < bgr.rows; ++r) {
    const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(r);
    const uchar* t = trimap.ptr<uchar>(r);
    for (int c = 0; c < bgr.cols; ++c)
      if (t[c] == cv::GC_FGD) core[size_t(colour_bin(p[c]))] += 1, ++n;
  }
  if (n < 100) return;
  // A colour is the head's when its bin and the neighbouring ones hold a share of the core.
  const std::vector<float> near_core = spread_to_neighbours(core, 1.f);
  const float min_count = float(kForeignShare * n);
  cv::Mat kept = cut.mask.clone();
  const int rows = std::clamp(last_row, 0, bgr.rows);
  for (int r = 0; r < rows; ++r) {
    const cv::Vec3b* p = bgr.ptr<cv::Vec3b>(r);
    uchar* m = kept.ptr<uchar>(r);
    for (int c = 0; c < bgr.cols; ++c)
      if (m[c] && near_core[size_t(colour_bin(p[c]))] < min_count) m[c] = 0;
  }
  cv::morphologyEx(kept, kept, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  const std::vector<cv::Point> held = outline_holding(kept, seed);
  if (held.empty()) return;
  cv::Mat part = cv::Mat::zeros(kept.size(), CV_8U);
  cv::fillPoly(part, std::vector<std::vector<cv::Point>>{held}, cv::Scalar(255));
  cut.mask = part & cut.mask;  // holes filled, nothing added beyond the cut
  smooth_probability(cut);
}

}  // namespace

double scene_spill(const cv::Mat& mask, const cv::Rect2d& face) {
  if (!(face.width > 1 && face.height > 1))
    throw std::invalid_argument("scene_spill: the face box is empty");
  if (!mask.empty() && mask.type() != CV_8U)
    throw std::invalid_argument("scene_spill: expected a CV_8U mask");
  const cv::Point centre(int(face.x + face.width / 2), int(face.y + face.height / 2));
  if (mask.empty() || !cv::Rect(0, 0, mask.cols, mask.rows).contains(centre) ||
      mask.at<uchar>(centre) == 0)
    return 1.0;
  // A blob short of the face (its colours are the scene's) misses the head as well.
  const cv::Rect inner =
      cv::Rect(cv::Point(int(face.x + 0.2 * face.width), int(face.y)),
               cv::Point(int(face.br().x - 0.2 * face.width), int(face.br().y))) &
      cv::Rect(0, 0, mask.cols, mask.rows);
  if (inner.area() > 0 && cv::countNonZero(mask(inner)) < 0.8 * inner.area()) return 1.0;
  const double cx = face.x + face.width / 2, reach = 1.7 * face.width;
  const int last = std::min(mask.rows, int(face.br().y + 0.5 * face.height));
  long outside = 0;
  for (int r = 0; r < last; ++r) {
    const uchar* m = mask.ptr<uchar>(r);
    for (int c = 0; c < mask.cols; ++c) outside += m[c] && std::abs(c + 0.5 - cx) > reach;
  }
  return outside / face.area();
}

double head_width_to_depth(const cv::Mat& front_mask, const cv::Mat& side_mask,
                           const cv::Rect2d& face, double row_scale) {
  if (!(face.width > 1 && face.height > 1))
    throw std::invalid_argument("head_width_to_depth: the face box is empty");
  for (const cv::Mat* m : {&front_mask, &side_mask})
    if (!m->empty() && m->type() != CV_8U)
      throw std::invalid_argument("head_width_to_depth: expected CV_8U masks");
  if (!(row_scale > 0 && std::isfinite(row_scale)))
    throw std::invalid_argument("head_width_to_depth: row_scale must be positive");
  if (front_mask.empty() || side_mask.empty()) return 0.0;
  // The widest row of `mask` between front rows r0 and r1 (`scale`: front rows per mask row).
  const auto widest = [&](const cv::Mat& mask, double scale) {
    const RowExtent e = row_extent(mask);
    double w = 0;
    if (e.top < 0) return w;
    const int r0 = std::max(e.top, int(face.y / scale));
    const int r1 = std::min(e.bottom, int((face.y + 0.7 * face.height) / scale));
    for (int r = r0; r <= r1; ++r)
      if (e.left[r] >= 0) w = std::max(w, double(e.right[r] - e.left[r] + 1));
    return w * scale;  // side columns are side rows' pixels: in front pixels
  };
  const double width = widest(front_mask, 1.0), depth = widest(side_mask, row_scale);
  return width > 0 && depth > 0 ? width / depth : 0.0;
}

SceneCut cut_front(const cv::Mat& front, const cv::Rect2d& face, const cv::Mat& border) {
  require_bgr(front, "cut_front");
  require_face(face, front.size(), "cut_front");
  const double cx = face.x + face.width / 2, fw = face.width, fh = face.height;
  const double top = face.y, chin = face.br().y, down = 2.0 * front.rows;  // to the bottom
  const cv::Point2d head(cx, top + 0.15 * fh);  // the head's middle, hair included
  cv::Mat trimap(front.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  // Where the subject may reach: the head with big hair, the neck and shoulders below the chin.
  fill_ellipse(trimap, head, {1.5 * fw, 1.55 * fh}, cv::GC_PR_BGD);
  fill(trimap, {cx - 1.0 * fw, chin, 2.0 * fw, down}, cv::GC_PR_BGD);
  // Where it probably is: the head's core, the neck (unless the border colours say otherwise).
  fill(trimap, {cx - 0.6 * fw, chin, 1.2 * fw, down}, cv::GC_PR_FGD);
  fill_ellipse(trimap, head, {0.8 * fw, 1.1 * fh}, cv::GC_PR_FGD);
  border_prior(trimap, border);
  // Where it surely is: the inner face (eyes, nose, mouth, cheeks), the forehead or hair above
  // the brows, the throat below the chin.
  fill_ellipse(trimap, {cx, top + 0.4 * fh}, {0.33 * fw, 0.35 * fh}, cv::GC_FGD);
  fill(trimap, {cx - 0.4 * fw, top - 0.45 * fh, 0.8 * fw, 0.45 * fh}, cv::GC_FGD);
  fill(trimap, {cx - 0.25 * fw, top - 0.6 * fh, 0.5 * fw, 0.15 * fh}, cv::GC_FGD);
  fill(trimap, {cx - 0.15 * fw, chin + 0.2 * fh, 0.3 * fw, 0.3 * fh}, cv::GC_FGD);
  SceneCut cut = grab_cut(front, trimap, {cx - 2.4 * fw, top - 1.5 * fh, 4.8 * fw, down},
                          cv::Point(int(cx), int(top + 0.4 * fh)), int(fw / 15));
  drop_foreign_colours(front, trimap, int(chin), cv::Point(int(cx), int(top + 0.4 * fh)), cut);
  clip_to_symmetry(cut, cx, int(chin + 0.5 * fh), 0.05 * fw);
  return cut;
}

SideHint side_hint(const cv::Mat& front, const cv::Mat& mask, const cv::Rect2d& face,
                   double row_scale) {
  require_bgr(front, "side_hint");
  if (mask.empty() || mask.size() != front.size() || mask.type() != CV_8U)
    throw std::invalid_argument("side_hint: the front mask is empty or not the photo's size");
  if (!(row_scale > 0)) throw std::invalid_argument("side_hint: row_scale must be > 0");
  const RowExtent e = row_extent(mask);
  SideHint h;
  const int eyes = std::clamp(int(face.y + 0.2 * face.height), 0, front.rows - 1);
  const int chin = std::clamp(int(face.br().y), 0, front.rows - 1);
  if (e.top < 0 || e.left[eyes] < 0)
    throw std::invalid_argument("side_hint: the front cut does not reach the eyes");
  h.top = e.top / row_scale, h.chin = chin / row_scale, h.eyes = eyes / row_scale;
  h.head_width = (e.right[eyes] - e.left[eyes] + 1) / row_scale;
  h.colours = cv::Mat::zeros(1, kColourBins, CV_32F);
  double n = 0;
  for (int r = e.top; r <= chin; ++r) {
    const cv::Vec3b* p = front.ptr<cv::Vec3b>(r);
    const uchar* m = mask.ptr<uchar>(r);
    for (int c = 0; c < front.cols; ++c)
      if (m[c]) h.colours.at<float>(colour_bin(p[c])) += 1, ++n;
  }
  h.colours /= std::max(1.0, n);
  return h;
}

namespace {

// Where the subject's colours gather in the side photo: each pixel's share of subject (the
// subject's histogram against the side photo's own), summed over the head's rows and a head's
// depth of columns; the best window's centre.
struct SideHead {
  cv::Mat share;  // CV_32F, each pixel's share of subject, 0..1
  int centre = 0;
  double depth = 0;  // a head is deeper, nose to nape, than it is wide
};
// `whole`: the share of every row (for the cut's trimap); otherwise only of the head's rows.
SideHead find_side_head(const cv::Mat& side, const SideHint& hint, bool whole, const char* what) {
  require_bgr(side, what);
  const double hh = hint.chin - hint.top;
  if (!(hh > 1 && hint.head_width > 1) || hint.colours.total() != size_t(kColourBins))
    throw std::invalid_argument(std::string(what) +
                                ": the hint holds no head (rows, width or colours)");
  // The photo's own colour histogram from every other pixel of every other row, and each
  // colour's share of subject.
  std::vector<double> scene(kColourBins, 0.0);
  double n = 0;
  for (int r = 0; r < side.rows; r += 2) {
    const cv::Vec3b* p = side.ptr<cv::Vec3b>(r);
    for (int c = 0; c < side.cols; c += 2) scene[colour_bin(p[c])] += 1, ++n;
  }
  std::vector<float> share_of(scene.size());
  for (size_t b = 0; b < scene.size(); ++b) {
    const double s = hint.colours.at<float>(int(b));
    share_of[b] = float(s / (s + scene[b] / n + 1e-9));
  }
  const int r0 = std::clamp(int(hint.top + 0.1 * hh), 0, side.rows - 1);
  const int r1 = std::clamp(int(hint.chin), r0 + 1, side.rows);
  SideHead h;
  h.share = cv::Mat::zeros(side.size(), CV_32F);
  for (int r = whole ? 0 : r0; r < (whole ? side.rows : r1); ++r) {
    const cv::Vec3b* p = side.ptr<cv::Vec3b>(r);
    float* o = h.share.ptr<float>(r);
    for (int c = 0; c < side.cols; ++c) o[c] = share_of[colour_bin(p[c])];
  }
  // Column sums over the head's rows, then the best window of a head's depth (prefix sums).
  cv::Mat column;
  cv::reduce(h.share.rowRange(r0, r1), column, 0, cv::REDUCE_SUM, CV_64F);
  std::vector<double> prefix(side.cols + 1, 0.0);
  for (int c = 0; c < side.cols; ++c) prefix[c + 1] = prefix[c] + column.at<double>(c);
  h.depth = 1.3 * hint.head_width;
  const int half = std::max(1, int(h.depth / 2));
  double best = -1;
  for (int c = 0; c < side.cols; ++c) {
    const double sum = prefix[std::min(side.cols, c + half)] - prefix[std::max(0, c - half)];
    if (sum > best) best = sum, h.centre = c;
  }
  return h;
}

}  // namespace

double side_missed(const cv::Mat& side, const cv::Mat& mask, const SideHint& hint) {
  const SideHead h = find_side_head(side, hint, false, "side_missed");
  if (!mask.empty() && (mask.size() != side.size() || mask.type() != CV_8U))
    throw std::invalid_argument("side_missed: the mask is not a CV_8U map of the photo's size");
  const cv::Rect window = cv::Rect(cv::Point(int(h.centre - h.depth / 2), int(hint.eyes)),
                                   cv::Point(int(h.centre + h.depth / 2), int(hint.chin))) &
                          cv::Rect(0, 0, side.cols, side.rows);
  if (window.area() == 0) return 0.0;
  const cv::Mat subject = h.share(window) > 0.6f;
  const int n = cv::countNonZero(subject);
  if (n == 0) return 0.0;
  if (mask.empty()) return 1.0;
  return cv::countNonZero(subject & (mask(window) == 0)) / double(n);
}

SceneCut cut_side(const cv::Mat& side, const SideHint& hint, const cv::Mat& border) {
  const SideHead h = find_side_head(side, hint, true, "cut_side");
  const double hh = hint.chin - hint.top, depth = h.depth;
  const int xc = h.centre;
  const double mid = (hint.top + hint.chin) / 2, down = 2.0 * side.rows;
  const cv::Point2d head(xc, mid);
  cv::Mat trimap(side.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  fill_ellipse(trimap, head, {0.9 * depth, 0.8 * hh}, cv::GC_PR_BGD);
  fill(trimap, {xc - 0.65 * depth, hint.chin, 1.3 * depth, down}, cv::GC_PR_BGD);
  fill(trimap, {xc - 0.45 * depth, hint.chin, 0.9 * depth, down}, cv::GC_PR_FGD);
  // Colours that are more the scene's than the subject's start as scene too, outside the head's
  // core; where the border colours say background, inside it as well.
  trimap.setTo(cv::GC_PR_BGD, (trimap == cv::GC_PR_FGD) & (h.share < 0.5f));
  fill_ellipse(trimap, head, {0.5 * depth, 0.55 * hh}, cv::GC_PR_FGD);
  border_prior(trimap, border);
  // The middle of a head in profile (cheek, ear, the hair above) is surely the subject.
  fill_ellipse(trimap, {double(xc), hint.eyes + 0.1 * hh}, {0.2 * depth, 0.25 * hh}, cv::GC_FGD);
  return grab_cut(side, trimap, {xc - 1.6 * depth, hint.top - 0.5 * hh, 3.2 * depth, down},
                  cv::Point(xc, int(hint.eyes + 0.1 * hh)), int(hint.head_width / 20));
}

}  // namespace orthoface::vision
