#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Optional helper, never the default: the largest face found by OpenCV's Haar cascade
// (Debian opencv-data) in `bgr`; `profile` picks haarcascade_profileface.xml (faces looking
// image-left, as the cascade was trained) instead of haarcascade_frontalface_default.xml.
// Faces from a fifth of the photo's shorter side (or 100 px) up; a non-empty `within` limits the
// search to that part of the photo (clipped to it). std::nullopt when none is found. Throws
// std::invalid_argument when `bgr` is not a non-empty 8-bit BGR image, std::runtime_error naming
// the cascade file when it cannot be loaded. Safe to call from several threads.
std::optional<cv::Rect> haar_face(const cv::Mat& bgr, const std::string& cascade_dir, bool profile,
                                  const cv::Rect& within = {});

// Eye boxes (haarcascade_eye.xml) inside `face` of `bgr`, largest first. Same errors.
std::vector<cv::Rect> haar_eyes(const cv::Mat& bgr, const cv::Rect& face,
                                const std::string& cascade_dir);

}  // namespace orthoface::vision
