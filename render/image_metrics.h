#pragma once

#include <opencv2/core.hpp>

namespace orthoface::render {

// Peak signal-to-noise ratio in dB (peak 255) of `test` against `reference` over the pixels where
// `mask` (CV_8U, same size) is non-zero; an empty mask means the whole image. Both 8-bit with the
// same size and channels; the mean squared error runs over all channels. +infinity if identical.
// Throws std::invalid_argument on mismatched / empty images or a mask with no pixel set.
double psnr(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask = {});

// Mean structural similarity (Wang et al. 2004: 11x11 Gaussian window, sigma 1.5, K1 0.01,
// K2 0.03, L 255) of the luma of both images, averaged over the mask pixels (empty = all).
// 1 for identical images. Same input rules and errors as psnr().
double ssim(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask = {});

}  // namespace orthoface::render
