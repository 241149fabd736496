#include "judge/head_region.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::judge {

cv::Mat head_region(const cv::Mat& photo, const cv::Rect& face_box) {
  if (photo.empty() || photo.type() != CV_8UC3)
    throw std::invalid_argument("head_region: the photo must be 8-bit BGR and not empty");
  const cv::Rect frame(0, 0, photo.cols, photo.rows);
  if (face_box.width < 4 || face_box.height < 4 || (face_box & frame) != face_box)
    throw std::invalid_argument("head_region: the face box is not inside the photo");
  const double k = std::min(1.0, 480.0 / photo.cols);
  cv::Mat small;
  cv::resize(photo, small, {}, k, k, cv::INTER_AREA);
  auto scaled = [&](double x, double y, double w, double h) {
    return cv::Rect(int(std::lround(x * k)), int(std::lround(y * k)), int(std::lround(w * k)),
                    int(std::lround(h * k))) &
           cv::Rect(0, 0, small.cols, small.rows);
  };
  const double w = face_box.width, h = face_box.height;
  const cv::Rect box = scaled(face_box.x - 0.9 * w, face_box.y - 1.1 * h, 2.8 * w, 2.7 * h);
  const cv::Rect sure = scaled(face_box.x + 0.2 * w, face_box.y + 0.2 * h, 0.6 * w, 0.6 * h);
  cv::Mat mask(small.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  mask(box).setTo(cv::GC_PR_BGD);
  // The face box and the hair above it are probably head; its middle surely is.
  mask(scaled(face_box.x - 0.1 * w, face_box.y - 0.5 * h, 1.2 * w, 1.5 * h) & box)
      .setTo(cv::GC_PR_FGD);
  mask(sure).setTo(cv::GC_FGD);
  cv::Mat bgd, fgd;
  // A fixed k-means seed (the thread's cv::theRNG()): the region depends on the photo alone and
  // the caller's random state is left as it was.
  cv::RNG& rng = cv::theRNG();
  const uint64 caller_state = rng.state;
  rng.state = 0xffffffff;  // cv::RNG's default state, a fresh thread's
  cv::grabCut(small, mask, box, bgd, fgd, 5, cv::GC_INIT_WITH_MASK);
  rng.state = caller_state;
  cv::Mat head = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);
  // The part that holds the face.
  cv::Mat labels;
  cv::connectedComponents(head, labels, 8, CV_32S);
  const int face_label = labels.at<int>(sure.y + sure.height / 2, sure.x + sure.width / 2);
  head = face_label > 0 ? labels == face_label : cv::Mat::zeros(small.size(), CV_8U);
  cv::Mat full;
  cv::resize(head, full, photo.size(), 0, 0, cv::INTER_LINEAR);
  return full > 127;
}

double head_iou(const cv::Mat& view_mask, const cv::Mat& view_to_real, const cv::Mat& real_mask,
                double max_row) {
  for (const cv::Mat* m : {&view_mask, &real_mask})
    if (m->empty() || m->type() != CV_8UC1)
      throw std::invalid_argument("head_iou: the masks must be 8-bit single-channel, not empty");
  if (view_to_real.rows != 2 || view_to_real.cols != 3)
    throw std::invalid_argument("head_iou: the transform must be 2x3");
  cv::Mat carried;
  cv::warpAffine(view_mask, carried, view_to_real, real_mask.size(), cv::INTER_NEAREST,
                 cv::BORDER_CONSTANT, 0);
  const int rows = std::clamp(int(std::ceil(max_row)), 0, real_mask.rows);
  const cv::Mat a = carried.rowRange(0, rows) > 0, b = real_mask.rowRange(0, rows) > 0;
  const int uni = cv::countNonZero(a | b);
  return uni == 0 ? 0.0 : double(cv::countNonZero(a & b)) / uni;
}

double black_fraction(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U)
    throw std::invalid_argument("black_fraction: the image must be 8-bit and not empty");
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  cv::Mat lit = channels[0].clone();  // non-zero where any channel is
  for (size_t c = 1; c < channels.size(); ++c) lit |= channels[c];
  return double(image.total() - cv::countNonZero(lit)) / double(image.total());
}

}  // namespace orthoface::judge
