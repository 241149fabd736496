#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Reads an image file as 8-bit BGR (grey, 16-bit and alpha images are converted). Throws
// std::runtime_error naming `path` when the file is missing, unreadable or not an image.
cv::Mat read_image(const std::string& path);

// Converts any 1-, 3- or 4-channel 8/16-bit/float image to 8-bit BGR (16-bit is scaled by its
// maximum, float by 255 when its range is [0,1]). `what` names the input in errors. Throws
// std::invalid_argument when the image is empty, smaller than 32x32, larger than 20000 px per
// side, has an aspect ratio beyond 8:1, or has an unsupported channel count or depth.
cv::Mat to_bgr8(const cv::Mat& image, const std::string& what);

// 8-bit grey of a BGR image.
cv::Mat grey(const cv::Mat& bgr);

}  // namespace orthoface::vision
