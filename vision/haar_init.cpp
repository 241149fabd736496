#include "vision/haar_init.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <stdexcept>

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

namespace orthoface::vision {

namespace {

// Loaded cascades, kept for the process: parsing haarcascade_frontalface_default.xml takes
// about 20 ms, as long as a search. A classifier holds scratch buffers while it searches (not
// safe to share between threads), so each search leases one of its own and gives it back.
class CascadePool {
 public:
  static CascadePool& instance() {
    static CascadePool pool;
    return pool;
  }
  cv::CascadeClassifier lease(const std::string& path) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto& idle = idle_[path];
      if (!idle.empty()) {
        cv::CascadeClassifier c = idle.back();
        idle.pop_back();
        return c;
      }
    }
    cv::CascadeClassifier c;
    if (!c.load(path))
      throw std::runtime_error("Haar cascade '" + path +
                               "' cannot be loaded (install opencv-data)");
    return c;
  }
  void give_back(const std::string& path, cv::CascadeClassifier c) {
    std::lock_guard<std::mutex> lock(mutex_);
    idle_[path].push_back(std::move(c));
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::vector<cv::CascadeClassifier>> idle_;
};

// One cascade from the pool for the lifetime of this object.
class LeasedCascade {
 public:
  LeasedCascade(const std::string& dir, const std::string& file)
      : path_(dir + "/" + file), c_(CascadePool::instance().lease(path_)) {}
  ~LeasedCascade() { CascadePool::instance().give_back(path_, std::move(c_)); }
  LeasedCascade(const LeasedCascade&) = delete;
  LeasedCascade& operator=(const LeasedCascade&) = delete;
  cv::CascadeClassifier& get() { return c_; }

 private:
  std::string path_;
  cv::CascadeClassifier c_;
};

std::vector<cv::Rect> detect(cv::CascadeClassifier& c, const cv::Mat& grey, int min_side) {
  std::vector<cv::Rect> r;
  c.detectMultiScale(grey, r, 1.1, 4, 0, cv::Size(min_side, min_side));
  std::sort(r.begin(), r.end(),
            [](const cv::Rect& a, const cv::Rect& b) { return a.area() > b.area(); });
  return r;
}

void check_bgr(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("Haar cascade: the image must be a non-empty 8-bit BGR image");
}

}  // namespace

std::optional<cv::Rect> haar_face(const cv::Mat& bgr, const std::string& dir, bool profile,
                                  const cv::Rect& within) {
  check_bgr(bgr);
  LeasedCascade c(dir,
                  profile ? "haarcascade_profileface.xml" : "haarcascade_frontalface_default.xml");
  const cv::Rect area = within.empty() ? cv::Rect(0, 0, bgr.cols, bgr.rows)
                                       : within & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (area.empty()) return std::nullopt;
  cv::Mat g;
  cv::cvtColor(bgr(area), g, cv::COLOR_BGR2GRAY);
  cv::equalizeHist(g, g);
  // A face to model fills a fifth of the photo's shorter side or is 100 px wide; smaller
  // windows, most of the search's time, are not tried.
  const int min_side = std::max(24, std::min(std::min(bgr.cols, bgr.rows) / 5, 100));
  // Faces from a quarter of the shorter side first: the small windows are most of the search's
  // time. A face found there at least 1.3x that size is found as by the whole search (the
  // windows grouped into a face are within about 20 % of its size); any other outcome is
  // settled by the whole search.
  const int large = std::min(bgr.cols, bgr.rows) / 4;
  std::vector<cv::Rect> r;
  if (large > min_side) r = detect(c.get(), g, large);
  if (r.empty() || r.front().width < 1.3 * large) r = detect(c.get(), g, min_side);
  if (r.empty()) return std::nullopt;
  return r.front() + area.tl();
}

std::vector<cv::Rect> haar_eyes(const cv::Mat& bgr, const cv::Rect& face, const std::string& dir) {
  check_bgr(bgr);
  LeasedCascade c(dir, "haarcascade_eye.xml");
  const cv::Rect roi = face & cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (roi.area() == 0) return {};
  cv::Mat g;
  cv::cvtColor(bgr(roi), g, cv::COLOR_BGR2GRAY);
  auto r = detect(c.get(), g, std::max(8, roi.width / 10));
  for (auto& e : r) e += roi.tl();
  return r;
}

}  // namespace orthoface::vision
