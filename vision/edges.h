#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

struct EdgeOptions {
  double blur_sigma_px = 1.0;        // Gaussian smoothing before the Sobel operator (0 = none)
  double threshold_fraction = 0.08;  // edge if magnitude > fraction * 99th percentile (low on
                                     // purpose, seed 004 §4: noise edges are easier to delete)
  void check() const;                // throws std::invalid_argument on out-of-range values
};

// Sobel gradient and thresholded edges of one image (seed 004 §4).
// The images cover a region of the source image whose top-left pixel is `origin` (the whole
// image: origin (0, 0)); pixel (c, r) of gx is source pixel origin + (c, r).
struct EdgeImage {
  cv::Mat gx, gy;     // CV_32F, d/dx and d/dy in intensity units per pixel
  cv::Mat magnitude;  // CV_32F
  cv::Mat edges;      // CV_8U, 255 where magnitude > threshold
  double threshold = 0.0;
  cv::Point origin{0, 0};
};

// Edge image of a single-channel 8-bit or 32-bit float image. Throws std::invalid_argument on
// an empty or multi-channel image.
EdgeImage edge_image(const cv::Mat& image, const EdgeOptions& options = {});

// Same, computed inside `roi` only (clipped to the image): the images cover that region
// (origin = its top-left) and the threshold counts the pixels outside it as zero-gradient ones.
// Throws std::invalid_argument as above or when `roi` misses the image.
EdgeImage edge_image(const cv::Mat& image, const EdgeOptions& options, const cv::Rect& roi);

// Each point moved along its direction (one per point, any length) to the strongest colour step
// of `bgr` (8-bit BGR) within +-range_px: the step is the L1 colour difference across one pixel,
// located to a fraction of a pixel by a parabola through its peak. A point whose strongest step
// is below min_step (grey levels, summed over the channels) stays. Index coordinates (pixel
// (c, r) has its centre at (c, r)). Used to place a boundary found on the smoothed foreground
// probability on the photo's own edge (the smoothing widens the probability blob by ~1 px).
// Throws std::invalid_argument for an empty or non-BGR image, points and directions of
// different sizes, range_px outside (0, 20] or min_step < 0.
// The defaults are what the front silhouette and the side profile use.
constexpr double kSnapRangePx = 2.0;  // search range, pixels
constexpr double kSnapMinStep = 20;   // weakest step that counts (grey levels)
std::vector<cv::Point2d> snap_to_colour_step(const cv::Mat& bgr,
                                             const std::vector<cv::Point2d>& points,
                                             const std::vector<cv::Point2d>& directions,
                                             double range_px = kSnapRangePx,
                                             double min_step = kSnapMinStep);

// Bilinear sample of a CV_32F image at (x, y) in pixel-centre coordinates (pixel (c, r) has
// its centre at (c, r)); points outside are clamped to the border.
float sample(const cv::Mat& image32f, double x, double y);

}  // namespace orthoface::vision
