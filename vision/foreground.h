#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

struct SegmentOptions {
  double border_fraction = 0.04;    // width of the image strips that sample the background colours
  double min_head_fraction = 0.01;  // a head blob smaller than this share of the image is "none"
  bool sample_left = true;   // sample the left / right border strips for the background model
  bool sample_right = true;  // (off: that border is suspected to cut through the subject)
  void check() const;        // throws std::invalid_argument on out-of-range values
};

// Probability-like map (CV_32F, 0 = background, 1 = subject) of where the subject is.
// With `background` (an empty-scene frame of the same size, 8-bit BGR): background difference.
// Without (empty Mat): colours unlike those seen on the left, right and top image borders.
// Throws std::invalid_argument when `bgr` is not 8-bit BGR or `background` differs in size/type.
cv::Mat foreground_probability(const cv::Mat& bgr, const cv::Mat& background,
                               const SegmentOptions& options = {});

// The colour bins of the border model's histograms: 16 levels a channel (the top 4 bits),
// kColourBins in all; colour_bin gives a pixel's.
inline constexpr int kColourLevels = 16;
inline constexpr int kColourBins = kColourLevels * kColourLevels * kColourLevels;
inline int colour_bin(const cv::Vec3b& bgr) {
  return ((bgr[0] >> 4) * kColourLevels + (bgr[1] >> 4)) * kColourLevels + (bgr[2] >> 4);
}

// `counts` (kColourBins colour bins) with each bin's count kept and spread to its 26 neighbouring
// bins times `neighbour_weight`: sensor noise moves colours across bin borders. Throws
// std::invalid_argument when `counts` is not kColourBins long.
std::vector<float> spread_to_neighbours(const std::vector<float>& counts, float neighbour_weight);

// How many of the border model's 4096 colour bins (16 levels a channel) hold 95 % of the border
// strips' pixels, after the same 5x5 smoothing: a curtain or a wall shows a handful (FRMDB's
// studio photos 5-11, a plain sim background 1), a room or a street scores tens to a hundred.
// Above kBusyBorderColours the border colours are no model of the background: the scene behind
// the subject holds colours the strips never show, and the strips hold the subject's. Throws
// std::invalid_argument when `bgr` is not 8-bit BGR.
inline constexpr int kBusyBorderColours = 16;
int border_colour_count(const cv::Mat& bgr, const SegmentOptions& options = {});

// Binary mask (CV_8U 0/255) of the head blob: the largest central connected component of
// `probability` > 0.5 (its outer contour), holes filled. Empty Mat when nothing large enough
// is found.
// `num_blobs` (optional) gets how many blobs were at least half the chosen one's area.
cv::Mat head_mask(const cv::Mat& probability, const SegmentOptions& options = {},
                  int* num_blobs = nullptr);

// Skin-colour likelihood (CV_32F, 0..1) from YCrCb chroma (a wide Cr/Cb box).
cv::Mat skin_probability(const cv::Mat& bgr);

// One pixel's 8-bit YCrCb (ITU-R BT.601, as cv::COLOR_BGR2YCrCb) and its skin likelihood (the
// per-pixel rule of skin_probability).
struct YCrCb {
  uchar luma, cr, cb;
};
YCrCb to_ycrcb(const cv::Vec3b& bgr);
float skin_likelihood(const YCrCb& pixel);

}  // namespace orthoface::vision
