#pragma once
// 68 face landmarks (iBUG 300-W layout: 0-16 jaw, 17-26 brows, 27-35 nose, 36-47 eyes, 48-67
// mouth) from a trained network whose weights are MIT-licensed (vision/models/README.md):
// face-api.js's FaceLandmark68Net, run here in plain C++. The face is first found by OpenCV's
// Haar cascade (BSD, Debian opencv-data); the network then looks at a square crop around it,
// and the crop is re-centred on the landmarks it gives until they settle.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// The folder with face_landmark_68_model.bin and its manifest: $ORTHOFACE_MODELS when set, else
// the source tree's vision/models when it is there, else the installed copy
// (<prefix>/share/orthoface/models, the prefix set at build time).
std::string default_model_dir();

struct FaceLandmarks68 {
  std::array<cv::Point2d, 68> points;  // image pixels, origin top-left (pixel centre = index + 0.5)
  cv::Rect2d crop;                     // the square the network saw last
  double movement_px = 0;              // mean point movement of the last refinement step
};

class FaceLandmarker68 {
 public:
  // Throws std::runtime_error naming the file when the weights cannot be read or do not have
  // the network's shapes.
  explicit FaceLandmarker68(const std::string& model_dir = default_model_dir());
  ~FaceLandmarker68();
  FaceLandmarker68(FaceLandmarker68&&) noexcept;
  FaceLandmarker68& operator=(FaceLandmarker68&&) noexcept;

  // The network's 68 points for a square crop of `bgr` (may reach outside the image: zero
  // padding, as in training). Throws std::invalid_argument on an empty or non-8-bit image or an
  // empty crop.
  std::array<cv::Point2d, 68> in_crop(const cv::Mat& bgr, const cv::Rect2d& crop) const;

  // The largest frontal face (Haar cascade in `cascade_dir`), then crops refined from the
  // points (crop_from_points) up to `iterations` times; none when the cascade finds no face.
  // Same errors as in_crop; std::runtime_error when the cascade cannot be loaded.
  std::optional<FaceLandmarks68> detect(const cv::Mat& bgr, const std::string& cascade_dir,
                                        int iterations = 3) const;
  // The same from a first guess of the face's square (e.g. from the head's silhouette).
  FaceLandmarks68 detect_in(const cv::Mat& bgr, const cv::Rect2d& first_crop,
                            int iterations = 6) const;
  // detect_in's refinement continued from `from` (its points and last movement) for up to
  // `iterations` more crops: detect_in(b, c, n) equals refine(b, detect_in(b, c, 0), n). Same
  // errors as in_crop; std::invalid_argument when `iterations` is negative.
  FaceLandmarks68 refine(const cv::Mat& bgr, FaceLandmarks68 from, int iterations) const;

 private:
  struct Net;
  std::unique_ptr<Net> net_;
};

// One landmarker for the whole process, loaded from default_model_dir() on first use (its
// methods are const and safe to call from several threads); nullptr when the weights cannot be
// read.
const FaceLandmarker68* shared_landmarker();

// The square crop the network expects around a face whose 68 points are `p` (the face
// detector's box the network was trained on: brows to chin, jaw to jaw, centred).
cv::Rect2d crop_from_points(const std::array<cv::Point2d, 68>& p);

}  // namespace orthoface::vision
