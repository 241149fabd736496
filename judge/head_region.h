#pragma once
// The head as a silhouette, for judging whole-head views against real photos: the real photo's
// head (hair included) cut out by OpenCV's GrabCut seeded by the judge's face box, and the
// overlap of a view's head with it once the two are aligned by the eyes.

#include <opencv2/core.hpp>

namespace orthoface::judge {

// The head region of `photo` (8-bit BGR): GrabCut (5 iterations, at most 480 px wide) inside a
// box around `face_box` (0.9 face widths to each side, 1.1 face heights above, 0.6 below), the
// face box's inner 60 % sure head, the rest of the box maybe; the connected part that holds
// the face box's centre. CV_8U, 255 = head, the photo's size. Throws std::invalid_argument on an
// empty or non-BGR photo or a face box outside it.
cv::Mat head_region(const cv::Mat& photo, const cv::Rect& face_box);

// Intersection over union of `view_mask` (CV_8U, non-zero = the view's head) carried into the
// real photo by `view_to_real` (2x3 similarity, CV_64F) and `real_mask` (CV_8U, the real
// photo's size), both cut at `max_row` of the real photo (the chin: the neck and body below are
// not the head). 0 when both are empty there. Throws std::invalid_argument on empty masks,
// another type or a transform that is not 2x3.
double head_iou(const cv::Mat& view_mask, const cv::Mat& view_to_real, const cv::Mat& real_mask,
                double max_row);

// Share of the image's pixels that are pure black (every channel 0): a view composited into a
// scene should leave none. Throws std::invalid_argument on an empty image or one not 8-bit.
double black_fraction(const cv::Mat& image);

}  // namespace orthoface::judge
