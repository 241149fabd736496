#include "vision/haar_init.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

namespace orthoface::vision {

namespace {

cv::CascadeClassifier load(const std::string& dir, const std::string& file) {
  const std::string path = dir + "/" + file;
  cv::CascadeClassifier c;
  if (!c.load(path))
    throw std::runtime_error("Haar cascade '" + path + "' cannot be loaded (install opencv-data)");
  return c;
}

std::vector<cv::Rect> detect(cv::CascadeClassifier& c, const cv::Mat& grey, int min_side) {
  std::vector<cv::Rect> r;
  c.detectMultiScale(grey, r, 1.1, 4, 0, cv::Size(min_side, min_side));
  std::sort(r.begin(), r.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.area() > b.area(); });
  return r;
}

}  // namespace

std::optional<cv::Rect> haar_face(const cv::Mat& bgr, const std::string& dir, bool profile) {
  cv::CascadeClassifier c =
      load(dir, profile ? "haarcascade_profileface.xml" : "haarcascade_frontalface_default.xml");
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  cv::equalizeHist(g, g);
  const auto r = detect(c, g, std::max(24, std::min(g.cols, g.rows) / 8));
  if (r.empty()) return std::nullopt;
  return r.front();
}

std::vector<cv::Rect> haar_eyes(const cv::Mat& bgr, const cv::Rect& face, const std::string& dir) {
  cv::CascadeClassifier c = load(dir, "haarcascade_eye.xml");
  const cv::Rect roi = face & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (roi.area() == 0) return {};
  cv::Mat g;
  cv::cvtColor(bgr(roi), g, cv::COLOR_BGR2GRAY);
  auto r = detect(c, g, std::max(8, roi.width / 10));
  for (auto& e : r) e += roi.tl();
  return r;
}

}  // namespace orthoface::vision
