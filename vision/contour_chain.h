#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Per-row extremes of a binary mask (CV_8U, non-zero = inside): left[r] / right[r] are the
// first / last inside column of row r, or -1 when the row is empty.
struct RowExtent {
  std::vector<int> left, right;
  int top = -1, bottom = -1;  // first / last non-empty row, -1 when the mask is empty
};
RowExtent row_extent(const cv::Mat& mask);

// The outer contour of the mask's largest blob, walked from its top-most point toward the
// image left (the front of a profile that looks left) until it reaches `stop_row`.
// Points are pixel centres (index coordinates). Empty when the mask is empty.
std::vector<cv::Point2d> front_chain(const cv::Mat& mask, int stop_row);

// How strongly the silhouette's left and right sides stick out of a smooth curve over the
// rows [r0, r1): returns (peak of left side, peak of right side) in pixels. A profile's nose
// makes one side's peak large; a frontal face gives two small, similar peaks.
cv::Point2d side_protrusions(const RowExtent& extent, int r0, int r1);

// Horizontal offset (px) of the neck's middle (rows top + [1.0, 1.15] * head_height) from the
// middle of the widest head row above it: near 0 in a front view, large in a profile (the neck
// stands behind the face). 0 when those rows are empty.
double neck_offset(const RowExtent& extent, double head_height);

// Width of the widest row of the head part of a blob: rows from the top until the depth below
// it exceeds 0.9 x the widest row so far (shoulders further down do not count). With
// `stop_at_widening` (a front view, whose head sides run down vertically), also stop where,
// past half that depth, the blob widens by 1.5 px a row (shoulders, a hood around the head),
// taking the width from before the widening. A side view's blob legitimately widens there
// (nose, chin). 0 when empty.
double head_width(const RowExtent& extent, bool stop_at_widening = false);

// Polyline resampled at equal arc-length steps of `step_px` (> 0).
std::vector<cv::Point2d> resample(const std::vector<cv::Point2d>& polyline, double step_px);

}  // namespace orthoface::vision
