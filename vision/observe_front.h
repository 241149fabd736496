#pragma once

#include <opencv2/core.hpp>

#include "vision/observation.h"
#include "vision/observe.h"
#include "vision/side_profile.h"

namespace orthoface::vision {

// The front view's head blob: foreground probability, mask (empty when no head) and how many
// head-sized blobs were seen.
struct FrontHead {
  cv::Mat probability, mask;
  int blobs = 0;
};
FrontHead segment_front(const cv::Mat& front, const cv::Mat& background);

// Front half of observe(): boundary, centre line and features of `front` (8-bit BGR), using the
// side profile's rows (index coordinates of the side image, scaled by `row_scale` = front
// height / side height) as the shared-row guess of seed 004 eq. 1. Fills obs.front, the centre
// line and warnings. Throws std::invalid_argument when the front image is clearly a profile.
// `head` is segment_front(front, background).
void observe_front(const cv::Mat& front, const cv::Mat& background, const FrontHead& head,
                   const SideProfile& profile, double row_scale, const ObserveOptions& options,
                   FaceObservation& obs);

}  // namespace orthoface::vision
