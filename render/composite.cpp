#include "render/composite.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

namespace orthoface::render {
namespace {

std::string size_text(const cv::Mat& m) {
  return std::to_string(m.cols) + "x" + std::to_string(m.rows);
}

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

cv::Mat head_removed(const cv::Mat& photo, const cv::Mat& region, const cv::Mat& clean_plate,
                     const cv::Mat& subject) {
  require(!photo.empty() && photo.type() == CV_8UC3, "head_removed: the photo is not 8-bit BGR");
  require(region.type() == CV_8UC1 && region.size() == photo.size(),
          "head_removed: the region must be 8-bit single-channel of the photo's size " +
              size_text(photo) + ", not " + size_text(region));
  require(
      clean_plate.empty() || (clean_plate.type() == CV_8UC3 && clean_plate.size() == photo.size()),
      "head_removed: the clean plate must be 8-bit BGR of the photo's size " + size_text(photo) +
          ", not " + size_text(clean_plate));
  require(subject.empty() || (subject.type() == CV_8UC1 && subject.size() == photo.size()),
          "head_removed: the subject mask must be 8-bit single-channel of the photo's size " +
              size_text(photo) + ", not " + size_text(subject));
  const cv::Mat hole = region > 0;
  cv::Mat out = photo.clone();
  if (cv::countNonZero(hole) == 0) return out;
  if (!clean_plate.empty()) {
    clean_plate.copyTo(out, hole);
    return out;
  }
  // Half size: inpainting costs grow with the hole's area, and a background is smooth anyway.
  cv::Mat small, small_hole, filled, back;
  cv::resize(photo, small, {}, 0.5, 0.5, cv::INTER_AREA);
  const cv::Mat unknown = subject.empty() ? hole : (hole | (subject > 0));
  cv::resize(unknown, small_hole, small.size(), 0, 0, cv::INTER_NEAREST);
  cv::dilate(small_hole, small_hole, cv::Mat::ones(3, 3, CV_8U));
  cv::inpaint(small, small_hole, filled, 5, cv::INPAINT_TELEA);
  cv::resize(filled, back, photo.size(), 0, 0, cv::INTER_LINEAR);
  back.copyTo(out, hole);
  return out;
}

cv::Mat composite(const RenderResult& view, const cv::Mat& background, const CompositeOptions& o) {
  require(!view.image.empty() && view.image.type() == CV_8UC3,
          "composite: the view is not 8-bit BGR");
  require(view.mask.type() == CV_8UC1 && view.mask.size() == view.image.size(),
          "composite: the view's mask is not 8-bit single-channel of its size");
  require(background.type() == CV_8UC3 && background.size() == view.image.size(),
          "composite: the background must be 8-bit BGR of the view's size " +
              size_text(view.image) + ", not " + size_text(background));
  require(o.feather_px >= 0, "composite: feather_px must be >= 0");
  require(!(o.fade_to_row < o.fade_from_row) && !std::isnan(o.fade_from_row) &&
              !std::isnan(o.fade_to_row),
          "composite: fade_to_row must not be above fade_from_row");
  // Alpha is 0 off the mask (the feather only lowers it): outside the mask's bounding box the
  // background is copied and the work below covers the box alone (the same values as over the
  // whole image: the blur reads the pixels around the box).
  cv::Mat out = background.clone();
  const cv::Rect box = cv::boundingRect(view.mask);
  if (box.empty()) return out;
  const cv::Rect image(0, 0, view.mask.cols, view.mask.rows);
  const int pad = o.feather_px > 0 ? int(std::ceil(4 * o.feather_px)) + 2 : 0;
  const cv::Rect padded =
      cv::Rect(box.x - pad, box.y - pad, box.width + 2 * pad, box.height + 2 * pad) & image;
  cv::Mat alpha_padded;
  view.mask(padded).convertTo(alpha_padded, CV_32F, 1.0 / 255);
  cv::Mat alpha = alpha_padded(box - padded.tl());
  if (o.feather_px > 0) {
    // Inside the mask only: the edge fades inward, never onto pixels the view left empty.
    // The blur of the box reads its neighbours (up to its radius, < pad) in the parent image.
    cv::Mat whole = cv::Mat::zeros(view.mask.size(), CV_32F);
    alpha_padded.copyTo(whole(padded));
    cv::Mat soft;
    cv::GaussianBlur(whole(box), soft, cv::Size(0, 0), o.feather_px);
    alpha = cv::min(alpha, soft * 2.0f);
  }
  for (int y = 0; y < alpha.rows; ++y) {
    const double row = box.y + y + 0.5;
    if (!(row > o.fade_from_row)) continue;
    const double span = o.fade_to_row - o.fade_from_row;
    const double t = span > 0 ? std::clamp((row - o.fade_from_row) / span, 0.0, 1.0) : 1.0;
    alpha.row(y) *= float(1 - t * t * (3 - 2 * t));
  }
  for (int y = 0; y < box.height; ++y) {
    const auto* a = alpha.ptr<float>(y);
    const auto* f = view.image.ptr<cv::Vec3b>(box.y + y) + box.x;
    const auto* b = background.ptr<cv::Vec3b>(box.y + y) + box.x;
    auto* o = out.ptr<cv::Vec3b>(box.y + y) + box.x;
    for (int x = 0; x < box.width; ++x) {
      if (a[x] == 0) continue;  // the background, as a * f + (1 - a) * b gives it
      if (a[x] == 1) {
        o[x] = f[x];
        continue;
      }
      for (int c = 0; c < 3; ++c)
        o[x][c] = cv::saturate_cast<uchar>(a[x] * f[x][c] + (1 - a[x]) * b[x][c]);
    }
  }
  return out;
}

cv::Mat fitted(const cv::Mat& image, int width, int height) {
  require(!image.empty(), "fitted: the image is empty");
  require(width > 0 && height > 0, "fitted: the size must be positive");
  if (image.cols == width && image.rows == height) return image.clone();
  const double s = std::min(double(width) / image.cols, double(height) / image.rows);
  cv::Mat scaled;
  cv::resize(image, scaled, {}, s, s, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  cv::Mat out(height, width, image.type(), cv::Scalar::all(0));
  const cv::Rect at((width - scaled.cols) / 2, (height - scaled.rows) / 2,
                    std::min(scaled.cols, width), std::min(scaled.rows, height));
  scaled(cv::Rect(0, 0, at.width, at.height)).copyTo(out(at));
  return out;
}

}  // namespace orthoface::render
