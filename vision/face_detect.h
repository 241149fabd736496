#pragma once
// Faces in a photo, for checking input before anything is modelled: dlib's HOG face detector
// (Dalal-Triggs HOG + linear SVM, five sub-detectors from frontal to about 60 degrees turned;
// the weights are part of the dlib library, Boost licence). Only the detector: dlib's 68-point
// predictor (trained on data excluding commercial use) stays with the judge.

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

struct DetectedFace {
  cv::Rect2d box;  // image pixels, origin top-left
  double score;    // the SVM's margin; 0 is dlib's own threshold
};

// Every face scoring at least `min_score`, highest score first. The photo is scaled so that
// faces from about 1/7 of its shorter side up are found (dlib's window is 80 px; a face to model
// fills more of the photo than that): small photos are upsampled, large ones reduced. Throws
// std::invalid_argument on an empty image or a pixel type other than 8-bit grey / BGR.
std::vector<DetectedFace> detect_faces(const cv::Mat& image, double min_score = 0.0);

// Decodes the detector now (about 0.3 s, once per process; thread-safe), e.g. on another thread
// while the photos are observed, so that detect_faces does not wait for it later.
void prepare_face_detector();

}  // namespace orthoface::vision
