#pragma once

#include <opencv2/core.hpp>

namespace orthoface::vision {

struct EdgeOptions {
  double blur_sigma_px = 1.0;       // Gaussian smoothing before the Sobel operator (0 = none)
  double threshold_fraction = 0.08; // edge if magnitude > fraction * 99th percentile (low on
                                    // purpose, seed 004 §4: noise edges are easier to delete)
  void check() const;               // throws std::invalid_argument on out-of-range values
};

// Sobel gradient and thresholded edges of one image (seed 004 §4).
// The images cover a region of the source image whose top-left pixel is `origin` (the whole
// image: origin (0, 0)); pixel (c, r) of gx is source pixel origin + (c, r).
struct EdgeImage {
  cv::Mat gx, gy;      // CV_32F, d/dx and d/dy in intensity units per pixel
  cv::Mat magnitude;   // CV_32F
  cv::Mat edges;       // CV_8U, 255 where magnitude > threshold
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

// Bilinear sample of a CV_32F image at (x, y) in pixel-centre coordinates (pixel (c, r) has
// its centre at (c, r)); points outside are clamped to the border.
float sample(const cv::Mat& image32f, double x, double y);

}  // namespace orthoface::vision
