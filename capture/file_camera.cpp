#include "capture/file_camera.h"

#include "capture/v4l2_camera.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <opencv2/imgproc.hpp>

namespace orthoface::capture {
namespace {

// The file's fourcc, or "BGR3" when it has none (image sequences, raw streams).
std::string fourcc_text(double code) {
  const std::string name = fourcc_name(static_cast<unsigned>(code));
  for (const char c : name)
    if (c < 0x20 || c > 0x7E) return "BGR3";
  return name;
}

void sleep_s(double s) {
  if (s > 0) std::this_thread::sleep_for(std::chrono::duration<double>(s));
}

}  // namespace

FileCamera::FileCamera(const std::string& id) : id_(id) {
  if (id.rfind("file:", 0) != 0) fail("not a file: camera id");
  path_ = id.substr(5);
  if (const size_t q = path_.rfind('?'); q != std::string::npos) {
    std::stringstream options(path_.substr(q + 1));
    path_ = path_.substr(0, q);
    for (std::string option; std::getline(options, option, '&');) {
      if (option == "loop") {
        loop_ = true;
      } else if (option.rfind("fps=", 0) == 0) {
        try {
          size_t used = 0;
          fps_ = std::stod(option.substr(4), &used);
          if (used != option.size() - 4) fps_ = 0;
        } catch (const std::exception&) {
          fps_ = 0;
        }
        if (!(fps_ > 0 && fps_ <= 1000)) fail("fps= must be a number in (0, 1000]: " + option);
      } else {
        fail("unknown option '" + option + "' (expected loop or fps=N)");
      }
    }
  }
  if (path_.empty()) fail("no file named");
  const bool sequence = path_.find('%') != std::string::npos;
  // OpenCV gives an image sequence a rate of 1 fps, a placeholder: the rate must be said.
  if (sequence && fps_ == 0) fail("an image sequence has no frame rate: add ?fps=N");
  if (!sequence && !std::filesystem::is_regular_file(path_)) fail("no such file");
  open_capture();
  cv::Mat first;
  if (!capture_.read(first) || first.empty()) fail("holds no frame");
  if (fps_ == 0) {
    fps_ = capture_.get(cv::CAP_PROP_FPS);
    if (!(fps_ > 0 && fps_ <= 1000)) fail("the file gives no usable frame rate: add ?fps=N");
  }
  format_.fourcc = fourcc_text(capture_.get(cv::CAP_PROP_FOURCC));
  format_.width = first.cols;
  format_.height = first.rows;
  format_.fps = fps_;
  capture_.release();
}

void FileCamera::fail(const std::string& what) const {
  throw std::runtime_error("camera " + id_ + ": " + what);
}

void FileCamera::open_capture() {
  // The backend is named: left to choose, OpenCV tries GStreamer first, which logs its own
  // errors for every file it cannot read.
  const bool sequence = path_.find('%') != std::string::npos;
  try {
    capture_.open(path_, sequence ? cv::CAP_IMAGES : cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
  }
  if (!capture_.isOpened())
    fail(sequence ? "no image of the sequence can be read (the pattern's first number is 0 or 1)"
                  : "not a video OpenCV can read");
  in_pass_ = 0;
  last_file_time_s_ = -1;
}

void FileCamera::start(const CameraFormat& format) {
  if (format.width != format_.width || format.height != format_.height)
    fail("plays " + std::to_string(format_.width) + "x" + std::to_string(format_.height) +
         ", not " + std::to_string(format.width) + "x" + std::to_string(format.height));
  stop();
  open_capture();
  started_ = true;
  start_s_ = monotonic_now_s();
  delivered_ = 0;
  pass_offset_s_ = 0;
}

bool FileCamera::read_next() {
  cv::Mat image;
  bool ok = capture_.read(image) && !image.empty();
  if (!ok && loop_ && in_pass_ > 0) {
    // The next pass starts one frame period after the last frame of this one.
    pass_offset_s_ += std::max(last_file_time_s_, 0.0) + 1.0 / fps_;
    capture_.release();
    open_capture();
    ok = capture_.read(image) && !image.empty();
  }
  if (!ok) return false;
  // The frame's own time in the file when the file keeps one, else its place at fps_.
  double t = capture_.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
  if (!(t > last_file_time_s_) || !std::isfinite(t))
    t = in_pass_ == 0 ? 0.0 : last_file_time_s_ + 1.0 / fps_;
  last_file_time_s_ = t;
  ++in_pass_;
  if (image.channels() == 1) cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  if (image.depth() != CV_8U)
    image.convertTo(image, CV_8U, image.depth() == CV_16U ? 1 / 257.0 : 1);
  pending_.image = image;
  pending_.timestamp_s = start_s_ + pass_offset_s_ + t;
  pending_.sequence = delivered_;
  has_pending_ = true;
  return true;
}

FrameResult FileCamera::next_frame(double timeout_s) {
  if (!started_) fail("next_frame before start");
  FrameResult r;
  if (!has_pending_ && !read_next()) {
    r.status = FrameStatus::Disconnected;
    r.message =
        "camera " + id_ + ": end of the file after " + std::to_string(delivered_) + " frames";
    return r;
  }
  if (pending_.image.cols != format_.width || pending_.image.rows != format_.height) {
    r.status = FrameStatus::Disconnected;
    r.message = "camera " + id_ + ": frame " + std::to_string(delivered_) + " is " +
                std::to_string(pending_.image.cols) + "x" + std::to_string(pending_.image.rows) +
                ", the file began at " + std::to_string(format_.width) + "x" +
                std::to_string(format_.height);
    return r;
  }
  const double wait = pending_.timestamp_s - monotonic_now_s();
  if (wait > timeout_s) {
    sleep_s(timeout_s);
    r.message = "camera " + id_ + ": the next frame is not due yet";
    return r;  // Timeout; the frame stays pending
  }
  sleep_s(wait);
  r.status = FrameStatus::Ok;
  r.frame = std::move(pending_);
  has_pending_ = false;
  ++delivered_;
  return r;
}

void FileCamera::stop() {
  started_ = false;
  has_pending_ = false;
  capture_.release();
}

}  // namespace orthoface::capture
