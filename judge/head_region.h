#pragma once
// The head as a silhouette, for judging whole-head views against real photos: the real photo's
// head (hair included) cut out by OpenCV's GrabCut seeded by the judge's face box, and the
// overlap of a view's head with it once the two are aligned by the eyes.

#include <opencv2/core.hpp>

#include "judge/face_judge.h"

namespace orthoface::judge {

// The head region of `photo` (8-bit BGR): GrabCut (5 iterations, at most 480 px wide) seeded
// around `face_box`. With dlib's 68 `face_points` (image pixels): surely head inside the hull
// of the inner features (points 17..67), probably head inside an ellipse set by the face and its
// turn (to the crown 0.8 brow-to-chin heights above the brows; behind the jaw 0.35 eye
// distances on a frontal face, 1.3 on a turned one; beyond the nose side 0.35 .. 0.15). Without
// them: the box's inner 60 % surely head, an ellipse 1.15 face widths and 1.1 heights round
// the box probably head. Then probably background out to a head's reach (1.4 widths beside the
// box, 1.1 heights above, 0.9 below), surely background beyond it and along the frame's top
// and sides; the connected part that holds the face. The wide "probably head" keeps dark
// hair's colours out of the background's model, which a tight one taught it (the hair then fell
// to the background). CV_8U, 255 = head, the photo's size. Throws std::invalid_argument on an
// empty or non-BGR photo, a face box outside it or a face point that is not a number or lies
// more than the photo's size beyond its edges.
cv::Mat head_region(const cv::Mat& photo, const cv::Rect& face_box,
                    const Landmarks68* face_points = nullptr);

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
