#include "vision/face_detect.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/image_transforms/image_pyramid.h>
#include <opencv2/imgproc.hpp>

#include "vision/face_landmarks68.h"

namespace orthoface::vision {

namespace {

constexpr double kMinFaceFraction = 7;  // smallest face found: 1/7 of the shorter side
// Crops refined from the network's own points after its first pass, at most, as the front's
// (observe_front.cpp): the turn index needs no more (seven moved the input check's side angles
// by up to 11 degrees and none of its outcomes, input_check_bench).
constexpr int kRefinements = 3;

// Decoding dlib's embedded detector takes about 0.3 s: once per process (observe() does it
// first, on the thread that finds the side photo's face while the front is segmented).
const dlib::frontal_face_detector& decoded_detector() {
  static const dlib::frontal_face_detector decoded = dlib::get_frontal_face_detector();
  return decoded;
}

}  // namespace

std::vector<DetectedFace> detect_faces(const cv::Mat& image, double min_score, int coarser_levels) {
  if (coarser_levels < 0 || coarser_levels > 8)
    throw std::invalid_argument("face detector: coarser_levels must be in [0, 8], got " +
                                std::to_string(coarser_levels));
  if (image.empty()) throw std::invalid_argument("face detector: the image is empty");
  if (image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 1))
    throw std::invalid_argument("face detector: the image must be 8-bit BGR or grey");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  // dlib's window is 80 px: a face 1/7 of the shorter side must be at least that.
  const double scale = 80.0 * kMinFaceFraction / std::min(grey.rows, grey.cols);
  cv::Mat scaled;
  cv::resize(grey, scaled, cv::Size(), scale, scale, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  dlib::array2d<unsigned char> img(scaled.rows, scaled.cols);
  for (int r = 0; r < scaled.rows; ++r)
    std::copy_n(scaled.ptr<unsigned char>(r), scaled.cols, &img[r][0]);
  // The detector's image pyramid (each level 5/6 of the one before) without its finest levels:
  // the same levels, so the same scores, for every face they hold.
  using Pyramid = dlib::pyramid_down<6>;
  const Pyramid pyramid;
  for (int k = 0; k < coarser_levels; ++k) {
    dlib::array2d<unsigned char> down;
    pyramid(img, down);
    if (down.nr() < 80 || down.nc() < 80) return {};  // smaller than the detector's window
    dlib::swap(img, down);
  }
  // Each caller its own copy (cheap): the detector keeps scratch buffers.
  dlib::frontal_face_detector detector = decoded_detector();
  std::vector<dlib::rect_detection> found;
  detector(img, found, min_score);
  std::vector<DetectedFace> faces;
  for (const auto& d : found) {
    // dlib's rectangle includes its right / bottom pixel: the box ends one past them.
    const dlib::drectangle b = pyramid.rect_up(
        dlib::drectangle(d.rect.left(), d.rect.top(), d.rect.right() + 1, d.rect.bottom() + 1),
        coarser_levels);
    faces.push_back(
        {cv::Rect2d(b.left() / scale, b.top() / scale, b.width() / scale, b.height() / scale),
         d.detection_confidence});
  }
  std::sort(faces.begin(), faces.end(),
            [](const DetectedFace& a, const DetectedFace& b) { return a.score > b.score; });
  return faces;
}

double turn_index(cv::Point2d left, cv::Point2d right, cv::Point2d tip) {
  const double half = 0.5 * cv::norm(right - left);
  if (!(half > 1e-9)) throw std::invalid_argument("turn index: the eye corners coincide");
  const cv::Point2d axis = (right - left) / (2 * half);
  return (tip - (left + right) * 0.5).dot(axis) / half;
}

FoundFace find_face(const cv::Mat& image, int coarser_levels) {
  const std::vector<DetectedFace> faces = detect_faces(image, 0.0, coarser_levels);
  FoundFace out;
  const DetectedFace* widest = nullptr;
  for (const auto& f : faces)
    if (!widest || f.box.width > widest->box.width) widest = &f;
  if (!widest) return out;
  // A person far behind does not count, a second sitter does.
  for (const auto& f : faces) out.faces += f.box.width >= 0.5 * widest->box.width;
  out.box = widest->box;
  out.score = widest->score;
  const FaceLandmarker68* net = shared_landmarker();
  if (!net) return out;
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  const double side = 1.2 * std::max(out.box.width, out.box.height);
  const cv::Point2d c = (out.box.tl() + out.box.br()) * 0.5;
  const FaceLandmarks68 f =
      net->detect_in(bgr, {c.x - side / 2, c.y - side / 2, side, side}, kRefinements);
  out.points.assign(f.points.begin(), f.points.end());
  if (cv::norm(f.points[45] - f.points[36]) > 1e-6)
    out.turn = turn_index(f.points[36], f.points[45], f.points[30]);
  return out;
}

}  // namespace orthoface::vision
