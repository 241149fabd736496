#include "judge/face_judge.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <vector>

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/image_transforms.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace orthoface::judge {

struct FaceJudge::Impl {
  dlib::frontal_face_detector detector = dlib::get_frontal_face_detector();
  dlib::shape_predictor predictor;
};

FaceJudge::FaceJudge(const std::string& predictor_path) : impl_(std::make_unique<Impl>()) {
  if (!std::filesystem::is_regular_file(predictor_path))
    throw std::runtime_error("face judge: no shape predictor at " + predictor_path +
                             " (Debian package libdlib-data)");
  try {
    dlib::deserialize(predictor_path) >> impl_->predictor;
  } catch (const std::exception& e) {
    throw std::runtime_error("face judge: cannot read shape predictor " + predictor_path + ": " +
                             e.what());
  }
}

FaceJudge::~FaceJudge() = default;

std::optional<FaceFound> FaceJudge::largest_face(const cv::Mat& image) const {
  return search(image).face;
}

FaceSearch FaceJudge::search(const cv::Mat& image) const {
  if (image.empty()) throw std::invalid_argument("face judge: the image is empty");
  if (image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 1))
    throw std::invalid_argument("face judge: the image must be 8-bit BGR or grey");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  dlib::array2d<unsigned char> img(grey.rows, grey.cols);
  for (int r = 0; r < grey.rows; ++r)
    for (int c = 0; c < grey.cols; ++c) img[r][c] = grey.at<unsigned char>(r, c);
  // One upsampling: faces down to about 40 px wide are found (dlib's examples do the same).
  dlib::pyramid_up(img);
  // Windows down to kNoFaceScore for the score; those at dlib's own threshold (0) are faces.
  std::vector<dlib::rect_detection> windows;
  impl_->detector(img, windows, kNoFaceScore);
  FaceSearch out;
  std::vector<dlib::rectangle> faces;
  for (const auto& w : windows) {
    out.score = std::max(out.score, w.detection_confidence);
    if (w.detection_confidence >= 0) faces.push_back(w.rect);
  }
  if (faces.empty()) return out;
  const dlib::rectangle* best = &faces[0];
  for (const auto& f : faces)
    if (f.area() > best->area()) best = &f;
  const dlib::full_object_detection shape = impl_->predictor(img, *best);
  FaceFound found;
  found.faces = int(faces.size());
  found.box = cv::Rect(int(best->left() / 2), int(best->top() / 2), int(best->width() / 2),
                       int(best->height() / 2));
  for (unsigned k = 0; k < 68 && k < shape.num_parts(); ++k)
    found.points[k] = cv::Point2d(shape.part(k).x() / 2.0, shape.part(k).y() / 2.0);
  out.face = found;
  return out;
}

bool predictor_available(const std::string& path) { return std::filesystem::is_regular_file(path); }

double shape_nme(const Landmarks68& view, const Landmarks68& real) {
  const double iod = cv::norm(real[36] - real[45]);
  if (!(iod > 1e-6)) throw std::invalid_argument("shape NME: the real outer eye corners coincide");
  std::vector<cv::Point2f> from, to;
  for (int k = 36; k <= 47; ++k) {
    from.emplace_back(float(view[k].x), float(view[k].y));
    to.emplace_back(float(real[k].x), float(real[k].y));
  }
  const cv::Mat t = cv::estimateAffinePartial2D(from, to, cv::noArray(), cv::LMEDS);
  if (t.empty()) throw std::invalid_argument("shape NME: no similarity fits the eye points");
  double sum = 0;
  int n = 0;
  auto add = [&](int a, int b) {
    for (int k = a; k <= b; ++k, ++n) {
      const cv::Point2d p = view[k];
      const cv::Point2d q(t.at<double>(0, 0) * p.x + t.at<double>(0, 1) * p.y + t.at<double>(0, 2),
                          t.at<double>(1, 0) * p.x + t.at<double>(1, 1) * p.y + t.at<double>(1, 2));
      sum += cv::norm(q - real[k]);
    }
  };
  add(0, 16);
  add(27, 35);
  add(48, 67);
  return sum / n / iod;
}

double shape_nme_or_miss(const std::optional<FaceFound>& view, const Landmarks68& real) {
  return view ? shape_nme(view->points, real) : 1.0;
}

double nose_between_eyes(const Landmarks68& p) {
  const double span = p[45].x - p[36].x;
  return span == 0 ? std::numeric_limits<double>::quiet_NaN() : (p[30].x - p[36].x) / span;
}

}  // namespace orthoface::judge
