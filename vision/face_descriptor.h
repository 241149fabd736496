#pragma once
// A face's identity as 128 numbers: face-api.js's FaceRecognitionNet (a ResNet-34 in the manner
// of dlib's face recogniser; weights MIT-licensed, vision/models/README.md), run here in plain C++.
// Two photos of one person seen from the front to about 45 degrees lie within about 0.55 of each
// other (Euclidean), different people mostly beyond (docs/input_check.md gives the figures on
// real photos; profiles are not matched).

#include <array>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "vision/face_landmarks68.h"

namespace orthoface::vision {

using FaceDescriptor = std::array<float, 128>;

// Euclidean distance between two descriptors.
double descriptor_distance(const FaceDescriptor& a, const FaceDescriptor& b);

// dlib's alignment crop of a face from its 68 points (iBUG layout), as face-api.js takes it:
// side = the mean distance from the mouth's centre to the two eyes' centres / 0.45, its left /
// top edge 0.5 / 0.43 of the side left of / above the mean of those three centres, clipped to
// the image (`image`). Empty when nothing of it lies inside.
cv::Rect face_descriptor_crop(const std::array<cv::Point2d, 68>& points, cv::Size image);

class FaceDescriber {
 public:
  // Throws std::runtime_error naming the file when the weights cannot be read or do not have
  // the network's shapes.
  explicit FaceDescriber(const std::string& model_dir = default_model_dir());
  ~FaceDescriber();
  FaceDescriber(FaceDescriber&&) noexcept;
  FaceDescriber& operator=(FaceDescriber&&) noexcept;

  // The descriptor of a face crop (8-bit BGR, any size): padded with black to a square about
  // its centre and resized to the network's 150 x 150. Throws std::invalid_argument on an empty
  // or non-8-bit-BGR image.
  FaceDescriptor describe_crop(const cv::Mat& bgr) const;
  // The descriptor of the face whose 68 points are given (face_descriptor_crop of `bgr`).
  // Throws std::invalid_argument on an empty or non-8-bit-BGR image, non-finite points or a
  // crop outside the image.
  FaceDescriptor describe(const cv::Mat& bgr, const std::array<cv::Point2d, 68>& points) const;

 private:
  struct Net;
  std::unique_ptr<Net> net_;
};

// One describer per process, loaded on first use from default_model_dir(); nullptr when the
// weights cannot be read.
const FaceDescriber* shared_describer();

}  // namespace orthoface::vision
