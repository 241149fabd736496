#pragma once

#include <functional>
#include <optional>

#include <opencv2/core.hpp>

#include "vision/face_landmarks68.h"

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

// The trained network's 68 points on the front photo's face as the Haar cascade finds it: they
// need nothing from the silhouette or the side photo, so observe() searches them on a thread of
// their own. Empty under FrontLandmarker::Filters, without the network's weights, or when no
// face (or no crop) is found; observe_front() then tries a crop from the silhouette.
struct FrontFace {
  std::optional<FaceLandmarks68> found;
};
// `within`: where to search (haar_face); empty for the whole photo. `first_pass`, when given, is
// called with the network's first points before they are refined (observe() hands the side
// profile its nose row from them, while the front's points are refined). Throws
// std::invalid_argument when `front` is not a non-empty 8-bit BGR image, std::runtime_error when
// the Haar cascade cannot be loaded.
FrontFace find_front_face(const cv::Mat& front, const ObserveOptions& options,
                          const cv::Rect& within = {},
                          const std::function<void(const FaceLandmarks68&)>& first_pass = {});

// Front half of observe(): boundary, centre line and features of `front` (8-bit BGR), using the
// side profile's rows (index coordinates of the side image, scaled by `row_scale` = front
// height / side height) as the shared-row guess of seed 004 eq. 1. Fills obs.front, the centre
// line and warnings. Throws std::invalid_argument when the front image is clearly a profile.
// `head` is segment_front(front, background), `face` find_front_face(front, options).
void observe_front(const cv::Mat& front, const cv::Mat& background, const FrontHead& head,
                   const FrontFace& face, const SideProfile& profile, double row_scale,
                   const ObserveOptions& options, FaceObservation& obs);

}  // namespace orthoface::vision
