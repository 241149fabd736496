#pragma once
// Faces in a photo, for checking input before anything is modelled: dlib's HOG face detector
// (Dalal-Triggs HOG + linear SVM, five sub-detectors from frontal to about 60 degrees turned;
// the weights are part of the dlib library, Boost licence). Only the detector: dlib's 68-point
// predictor (trained on data excluding commercial use) stays with the judge.

#include <vector>

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

struct DetectedFace {
  cv::Rect2d box;  // image pixels, origin top-left
  double score;    // the SVM's margin; 0 is dlib's own threshold
};

// Every face scoring at least `min_score`, highest score first. The photo is scaled so that
// faces from about 1/7 of its shorter side up are found (dlib's window is 80 px; a face to model
// fills more of the photo than that): small photos are upsampled, large ones reduced.
// `coarser_levels` > 0 leaves out that many of the finest levels of the detector's image pyramid
// (each 6/5 of the next): faces from 1/7 x 1.2^k of the shorter side up, with the same scores as
// a full search, in about 0.69^k of its time. Throws std::invalid_argument on an empty image, a
// pixel type other than 8-bit grey / BGR, or coarser_levels outside [0, 8].
std::vector<DetectedFace> detect_faces(const cv::Mat& image, double min_score = 0.0,
                                       int coarser_levels = 0);

// The turn index of a face from its outer eye corners and nose tip (image pixels): the nose
// tip's offset from the eyes' midpoint over half their distance, along the eye line. A head
// turned by t shows about kTurnPerTan x tan t (nose tip about 38 mm ahead of the eye corners,
// 90 mm apart): 0 frontal, 0.3 at 20 degrees, 0.85 at 45, large or undefined in profile. Signed:
// > 0 when the nose points toward the image right. Throws std::invalid_argument when the eye
// corners coincide.
inline constexpr double kTurnPerTan = 0.85;
double turn_index(cv::Point2d eye_image_left, cv::Point2d eye_image_right, cv::Point2d nose_tip);

// The widest face detect_faces finds (score >= 0) in an 8-bit BGR or grey photo, how many others
// are at least half as wide, and the landmark network's points and turn index on it;
// `coarser_levels` as for detect_faces. Same errors as detect_faces.
FoundFace find_face(const cv::Mat& image, int coarser_levels = 0);

}  // namespace orthoface::vision
