#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Optional helper, never the default: the largest face found by OpenCV's Haar cascade
// (Debian opencv-data) in `bgr`; `profile` picks haarcascade_profileface.xml (faces looking
// image-left, as the cascade was trained) instead of haarcascade_frontalface_default.xml.
// std::nullopt when none is found. Throws std::runtime_error naming the cascade file when it
// cannot be loaded.
std::optional<cv::Rect> haar_face(const cv::Mat& bgr, const std::string& cascade_dir, bool profile);

// Eye boxes (haarcascade_eye.xml) inside `face` of `bgr`, largest first. Same errors.
std::vector<cv::Rect> haar_eyes(const cv::Mat& bgr, const cv::Rect& face,
                                const std::string& cascade_dir);

}  // namespace orthoface::vision
