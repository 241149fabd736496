#pragma once

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

// Debug overlays of an observation on its two photos (8-bit BGR copies): boundary / profile in
// green, centre line in cyan, features as red dots with their names, mirrored ones in magenta,
// position-model guesses in yellow. Throws std::invalid_argument when an image is empty.
cv::Mat overlay_front(const cv::Mat& front, const FaceObservation& obs);
cv::Mat overlay_side(const cv::Mat& side, const FaceObservation& obs);

// Both overlays side by side (heights equalised), for one PNG.
cv::Mat overlay_pair(const cv::Mat& front, const cv::Mat& side, const FaceObservation& obs);

}  // namespace orthoface::vision
