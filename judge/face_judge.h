#pragma once
// The real-photo judge: an independent face landmarker (dlib's HOG face detector and its
// 68-point shape predictor, iBUG 300-W layout) scoring images the product made. It is a
// measuring instrument for benchmarks and tests only: the predictor's model
// (/usr/share/dlib/shape_predictor_68_face_landmarks.dat, Debian libdlib-data) was trained on
// data whose terms exclude commercial use, so the product does not link this.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace orthoface::judge {

// 68 points in the iBUG layout (0-16 jaw, 17-26 brows, 27-35 nose, 36-47 eyes, 48-67 mouth),
// image pixels, origin top-left.
using Landmarks68 = std::array<cv::Point2d, 68>;

constexpr const char* kDefaultPredictor = "/usr/share/dlib/shape_predictor_68_face_landmarks.dat";

struct FaceFound {
  cv::Rect box;  // the detector's box, in the image's pixels
  Landmarks68 points;
  int faces = 0;  // faces the detector found (the largest is the one described)
};

// One look for a face: the largest found (dlib's own threshold, detection confidence >= 0) and
// the best confidence any window reached down to kNoFaceScore, which stays continuous where
// "found" flips: a view a little better or worse than the last moves the score, not only the
// count.
constexpr double kNoFaceScore = -1.0;
struct FaceSearch {
  std::optional<FaceFound> face;
  double score = kNoFaceScore;  // dlib's detection confidence of the best window, >= kNoFaceScore
};

// dlib's detector + predictor, loaded once (about 0.5 s: the predictor is 100 MB).
class FaceJudge {
 public:
  // Throws std::runtime_error naming the file when the predictor cannot be read.
  explicit FaceJudge(const std::string& predictor_path = kDefaultPredictor);
  ~FaceJudge();
  FaceJudge(const FaceJudge&) = delete;
  FaceJudge& operator=(const FaceJudge&) = delete;

  // The largest face in an 8-bit BGR or grey image, detected after one 2x upsampling (as dlib's
  // own examples run it); none when no face is found. Throws std::invalid_argument on an empty
  // image or another pixel type.
  std::optional<FaceFound> largest_face(const cv::Mat& image) const;

  // The same, with the best detection confidence (FaceSearch). Same errors.
  FaceSearch search(const cv::Mat& image) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Whether the default predictor file is installed (tests skip without it).
bool predictor_available(const std::string& path = kDefaultPredictor);

// Shape error of `view` against `real`: a similarity transform fitted from the view's 12 eye
// points (36-47) onto the real ones (cv::estimateAffinePartial2D, LMEDS), then the mean distance
// over points 0-16, 27-35 and 48-67 after it, divided by the real outer-eye-corner distance
// (points 36 and 45). Throws std::invalid_argument when the real eye corners coincide or the
// transform cannot be fitted.
double shape_nme(const Landmarks68& view, const Landmarks68& real);

// NME of a view that may have no face: 1.0 when none was found (the judge's rule).
double shape_nme_or_miss(const std::optional<FaceFound>& view, const Landmarks68& real);

// Where the nose tip (iBUG 30) lies between the outer eye corners (36, 45) along the image's x:
// 0 at point 36, 1 at point 45, 0.5 on a frontal face, beyond 0..1 on a face turned past the
// nose's crossing of an eye; the head's turn as a camera saw it. NaN when the corners share a
// column.
double nose_between_eyes(const Landmarks68& points);

}  // namespace orthoface::judge
