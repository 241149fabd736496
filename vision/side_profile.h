#pragma once

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/observation.h"
#include "vision/profile_fit.h"

namespace orthoface::vision {

struct SideProfileOptions {
  double control_spacing_px = 5.0;  // arc length between the profile model's control points
  double min_head_height_px = 0.0;  // lower bound of the crown-to-chin height (e.g. the front
                                    // view's head width; 0 = from the blob alone)
  // The nose tip's row in the side photo as the front photo has it (the two photos' rows shared,
  // seed 004 eq. 1; on FRMDB's 26 pairs the side's tip lies 0.01-0.10 head heights above it);
  // < 0 unknown. The tip is then looked for near it first (find_profile_landmarks).
  double expected_nose_row = -1.0;
  ProfileFitOptions fit;  // the iterative fit; num_control/samples are set from length
  void check() const;     // throws std::invalid_argument on out-of-range values
};

// The front half of a profile in a side image whose face looks toward the image LEFT (callers
// mirror a right-facing image first). Index coordinates: pixel (c, r) has its centre at (c, r).
struct SideProfile {
  std::vector<cv::Point2d> curve;  // crown -> forehead -> nose -> lips -> chin -> throat, ~1 px
  double confidence = 0.0;         // share of the curve backed by edges, times a shape check
  double head_height_px = 0.0;     // estimated crown-to-chin height
  std::map<std::string, Feature2d> features;  // profile landmarks + ear (see vision/landmarks.h)
  std::vector<std::string> warnings;
};

// Profile of the head blob `mask` (CV_8U) in `bgr` (8-bit BGR), refined on the edges of the
// foreground probability `prob` (CV_32F) by the seed 004 §4 B-spline fit; profile landmarks from
// the curve's extrema and concavities. An empty mask gives an empty result with a warning.
// Throws std::invalid_argument when the sizes or types differ.
SideProfile side_profile(const cv::Mat& bgr, const cv::Mat& prob, const cv::Mat& mask,
                         const SideProfileOptions& options = {});

// Profile landmarks (kProfileLandmarkNames + chin_bottom) of sp.curve, added to sp.features:
// nose tip = most projecting point (within 0.16 head heights above and 0.12 below
// `expected_nose_row` when that holds a projecting point inside the band, else 0.35..0.85 head
// heights below the curve's top), nasion / subnasale = deepest concavities, lips and chin =
// alternating extrema of the projection, chin bottom = tangent at 45 deg under the chin,
// forehead top = skin-to-hair colour change along the curve. Missing ones add a warning.
// The stretch above the tip loses its bays (points with another point of that stretch well in
// front of them at their row: a notch in the blob), so sp.curve may come back shorter.
void find_profile_landmarks(const cv::Mat& bgr, SideProfile& sp, double expected_nose_row = -1.0);

// True when `curve` (a left-facing front profile, top to bottom, ~1 px steps) has a nose tip in
// the face band of a head `head_height_px` tall, below it the long backward run under the chin,
// and between the two a step back of at least kFaceStepBack x the head height behind the chord
// from tip to throat: the shape of a face. The back of a head or a hair / skin border does not
// have all three.
inline constexpr double kFaceStepBack = 0.015;
bool reads_as_face_profile(const std::vector<cv::Point2d>& curve, double head_height_px);

// True when the profile in `mask` (head blob of a side image) looks toward the image left;
// `confidence` (optional) gets 0..1 from how much one side's nose bump dominates.
bool profile_faces_left(const cv::Mat& mask, double* confidence = nullptr);
// Same, also voting with where the skin of `bgr` (8-bit BGR, size of `mask`; may be empty) lies
// in the blob: face skin in front, hair behind; `min_head_height_px` as in SideProfileOptions.
// Throws std::invalid_argument on a size mismatch or a negative height.
bool profile_faces_left(const cv::Mat& mask, const cv::Mat& bgr, double* confidence,
                        double min_head_height_px = 0.0);

}  // namespace orthoface::vision
