#include "vision/head_silhouette.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::vision {
namespace {

constexpr uint64 kGrabCutSeed = 0xffffffff;  // cv::RNG's default state, a fresh thread's

// `blob` grown by GrabCut into `box` (full-size pixels): the blob eroded is subject for certain,
// the blob and the box possibly, the rest background. The result keeps the component that holds
// the blob, holes filled.
cv::Mat grow(const cv::Mat& bgr, const cv::Mat& blob, const cv::Rect2d& box,
             const SilhouetteOptions& o) {
  const double s = std::min(1.0, o.work_width / bgr.cols);
  cv::Mat small, small_blob;
  cv::resize(bgr, small, {}, s, s, cv::INTER_AREA);
  cv::resize(blob, small_blob, small.size(), 0, 0, cv::INTER_NEAREST);
  const cv::Rect frame(0, 0, small.cols, small.rows);
  const cv::Rect b =
      cv::Rect(cv::Point(int(box.x * s), int(box.y * s)),
               cv::Point(int(std::ceil(box.br().x * s)), int(std::ceil(box.br().y * s)))) &
      frame;
  cv::Mat sure;
  cv::erode(small_blob, sure, cv::Mat::ones(7, 7, CV_8U));
  if (b.area() <= 0 || cv::countNonZero(sure) == 0) return blob.clone();
  cv::Mat mask(small.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  mask(b).setTo(cv::GC_PR_FGD);
  mask.setTo(cv::GC_PR_FGD, small_blob);
  mask.setTo(cv::GC_FGD, sure);
  cv::Mat bgd, fgd;
  // GrabCut seeds its colour models by k-means from this thread's cv::theRNG(): a fixed state
  // makes the silhouette depend on the photo alone, not on what ran on the thread before it (a
  // batch of pairs, a station's refits); the caller's state is put back.
  cv::RNG& rng = cv::theRNG();
  const uint64 caller_state = rng.state;
  rng.state = kGrabCutSeed;
  cv::grabCut(small, mask, cv::Rect(), bgd, fgd, o.iterations, cv::GC_INIT_WITH_MASK);
  rng.state = caller_state;
  cv::Mat subject = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);

  // The component that holds the sure subject, its holes filled.
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(subject, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  cv::Mat kept(small.size(), CV_8U, cv::Scalar(0));
  for (size_t i = 0; i < contours.size(); ++i) {
    cv::Mat one(small.size(), CV_8U, cv::Scalar(0));
    cv::drawContours(one, contours, int(i), cv::Scalar(255), cv::FILLED);
    if (cv::countNonZero(one & sure) > 0) kept |= one;
  }
  cv::Mat full;
  cv::resize(kept, full, bgr.size(), 0, 0, cv::INTER_LINEAR);
  return full > 127;
}

}  // namespace

void SilhouetteOptions::check() const {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("silhouette options: " + what);
  };
  if (!(work_width >= 32 && work_width <= 4096)) bad("work_width must be in [32, 4096]");
  if (iterations < 1 || iterations > 20) bad("iterations must be in [1, 20]");
  if (!(top_e > 0 && top_e <= 10)) bad("top_e must be in (0, 10]");
  if (!(half_width_e > 0 && half_width_e <= 10)) bad("half_width_e must be in (0, 10]");
  if (!(back_e > 0 && back_e <= 10)) bad("back_e must be in (0, 10]");
}

cv::Mat without_top_column(const cv::Mat& mask, int rows) {
  if (!mask.empty() && mask.type() != CV_8UC1)
    throw std::invalid_argument("top column: the mask is not 8-bit single-channel");
  if (rows < 2) throw std::invalid_argument("top column: rows must be at least 2");
  if (mask.empty() || rows > mask.rows) return mask.clone();
  const int top = cv::countNonZero(mask.row(0));
  if (top == 0) return mask.clone();
  for (int r = 1; r < rows; ++r)
    if (std::abs(cv::countNonZero(mask.row(r)) - top) > 0.1 * top) return mask.clone();
  int x0 = mask.cols, x1 = -1;
  for (int c = 0; c < mask.cols; ++c)
    if (mask.at<uchar>(0, c)) x0 = std::min(x0, c), x1 = std::max(x1, c);
  const int pad = int(std::ceil(0.1 * (x1 - x0 + 1)));
  const int c0 = std::max(0, x0 - pad), c1 = std::min(mask.cols - 1, x1 + pad);
  cv::Mat out = mask.clone();
  for (int r = 0; r < mask.rows && cv::countNonZero(mask.row(r)) < 1.5 * top; ++r)
    out.row(r).colRange(c0, c1 + 1).setTo(0);
  return out;
}

Silhouettes subject_silhouettes(const cv::Mat& front, const cv::Mat& side,
                                const FaceObservation& obs, const SilhouetteOptions& o) {
  o.check();
  for (auto [name, photo, view] :
       {std::tuple{"front", &front, &obs.front}, std::tuple{"side", &side, &obs.side}}) {
    const std::string what = std::string("silhouettes: the ") + name + " photo";
    if (photo->empty() || photo->type() != CV_8UC3)
      throw std::invalid_argument(what + " is not 8-bit BGR");
    if (photo->cols != view->width || photo->rows != view->height)
      throw std::invalid_argument(what + " is " + std::to_string(photo->cols) + "x" +
                                  std::to_string(photo->rows) + ", its observation " +
                                  std::to_string(view->width) + "x" + std::to_string(view->height));
  }
  Silhouettes out{obs.front_blob.clone(), obs.side_blob.clone()};
  const Feature2d* el = find_feature(obs.front.features, "eye_left_center");
  const Feature2d* er = find_feature(obs.front.features, "eye_right_center");
  if (!el || !er) return out;
  const double e = cv::norm(el->px - er->px);
  const double eye_row = 0.5 * (el->px.y + er->px.y);
  if (!(e > 2)) return out;
  const double centre_x = obs.centre_x_px + std::tan(obs.roll_rad) * (eye_row - obs.centre_y_px);
  const double top = eye_row - o.top_e * e;
  const cv::Rect2d front_box(centre_x - o.half_width_e * e, top, 2 * o.half_width_e * e,
                             front.rows - top);
  std::future<cv::Mat> side_grown;
  if (const Feature2d* nose = find_feature(obs.side.features, "nose_tip");
      nose && !obs.side_blob.empty()) {
    const double behind = o.back_e * e, before = 0.4 * e;
    const double x0 = obs.side_faces_left ? nose->px.x - before : nose->px.x - behind;
    const cv::Rect2d side_box(x0, top, behind + before, side.rows - top);
    side_grown = std::async(std::launch::async, grow, std::cref(side), std::cref(obs.side_blob),
                            side_box, std::cref(o));
  }
  if (!obs.front_blob.empty()) out.front = grow(front, obs.front_blob, front_box, o);
  if (side_grown.valid()) out.side = side_grown.get();
  // A column is told by keeping its width over half an eye distance.
  out.front = without_top_column(out.front, std::max(2, int(0.5 * e)));
  out.side = without_top_column(out.side, std::max(2, int(0.5 * e * side.rows / front.rows)));
  return out;
}

}  // namespace orthoface::vision
