#pragma once

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

// The side photo's subject mask from the profile (the side ViewObservation's boundary, forehead
// to throat, in the image as given): on each row the profile spans, the pixels from the profile
// backwards (toward the image right when the face points to the image left, `faces_left`, else
// toward the left); rows above and below it are all subject (not known there). CV_8U 0 / 255 of
// the view's size. Throws std::invalid_argument when the view has no size or fewer than 2
// profile points.
cv::Mat profile_mask(const ViewObservation& side, bool faces_left);

// profile_mask of the observation's side view when it has a profile for a side photo of
// `side_size`; an empty Mat (the whole photo) otherwise.
cv::Mat side_photo_mask(const FaceObservation& observation, cv::Size side_size);

}  // namespace orthoface::vision
