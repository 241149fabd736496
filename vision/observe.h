#pragma once

#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

// Where the side camera stands (DESIGN.md --side-camera): Left = at the subject's left (head
// +x), so the face looks toward the image left; Auto = decided from the side image.
enum class SideCamera { Auto, Left, Right };
// "auto" / "left" / "right" (--side-camera); throws std::invalid_argument naming the text
// otherwise.
SideCamera parse_side_camera(const std::string& name);

// Which detector gives the front view's eyes, brows, nose, mouth and chin.
enum class FrontLandmarker {
  Filters,    // seed 004 §4: a position model placed by the side profile's rows, local filters
  Network,    // a trained 68-point network (vision/face_landmarks68.h, MIT weights) on the face
              // the Haar cascade or the silhouette gives; the filters where it finds no face
  Consensus,  // both: each paired feature (eyes, brows, mouth and nose wings) and the centre
              // line from the filters where they agree with the network (within 6 % of the
              // eye distance: the filters lock onto the image's own edges), else the network's;
              // the midline rows from the profile as the filters place them
};
// "filters" / "network" / "consensus"; throws std::invalid_argument naming the text otherwise.
FrontLandmarker parse_front_landmarker(const std::string& name);
const char* front_landmarker_name(FrontLandmarker landmarker);

struct ObserveOptions {
  FrontLandmarker landmarker = FrontLandmarker::Consensus;
  cv::Mat background_front;  // optional empty-scene frames (same size as the photo): silhouettes
  cv::Mat background_side;   // then come from background difference instead of border colours
  SideCamera side_camera = SideCamera::Auto;
  bool use_haar = false;  // optional: OpenCV Haar cascades (opencv-data) check/initialise eyes
  std::string haar_dir = "/usr/share/opencv4/haarcascades";
  double max_size_ratio = 1.5;  // front / side image heights may differ at most by this factor
  // The user's front landmarks (names from vision/landmarks.h, front pixels as in the
  // observation): each replaces the detected feature (confidence 1, method "user") before
  // stereo and adaptation see it; a given symmetric pair re-fits the centre line. They must lie
  // in the front image (observe() throws std::invalid_argument otherwise).
  std::map<std::string, cv::Point2d> front_landmarks;
  void check() const;  // throws std::invalid_argument on out-of-range values or unknown names
};

// Seed 004 §4 on a front + side pair: silhouettes, profile, centre line and named features with
// confidences; pixels follow capture/camera_model.h (pixel centre = index + 0.5). Grey, 16-bit
// and 4-channel images are converted. Throws std::invalid_argument naming the input for empty,
// tiny or huge images, sizes too different, or a front image that is clearly a profile. A view
// without a face gives an observation with empty parts and warnings that say so.
FaceObservation observe(const cv::Mat& front, const cv::Mat& side,
                        const ObserveOptions& options = {});

// Front view alone (no side photo, e.g. a frontal face collection): boundary, centre line and
// front features; midline rows come from the position model (method "position-model", low
// confidence) instead of the side profile. Same input checks and conversions as observe();
// obs.side stays empty.
FaceObservation observe_front(const cv::Mat& front, const ObserveOptions& options = {});

// True when both outlines and every front feature and profile landmark are present with
// non-zero confidence (ears excluded); `missing` (optional) lists what is not.
bool is_complete(const FaceObservation& obs, std::string* missing = nullptr);

}  // namespace orthoface::vision
