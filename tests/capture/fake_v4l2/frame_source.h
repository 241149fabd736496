#pragma once
// Frames the fake V4L2 device serves: a frame file written by another process (the simulated
// rig), or a moving test pattern; encoded as YUYV or MJPEG.
#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fake_v4l2 {

class FrameSource {
 public:
  explicit FrameSource(std::string frame_file) : file_(std::move(frame_file)) {}
  // Writes frame `sequence` in `pixelformat` at width x height into dst (capacity bytes);
  // returns the bytes used, 0 if it does not fit.
  size_t fill(unsigned pixelformat, int width, int height, unsigned sequence, unsigned char* dst,
              size_t capacity);

 private:
  cv::Mat next_bgr(int width, int height, unsigned sequence);
  std::string file_;
  cv::Mat last_;  // last frame read from the file (kept when the file is being replaced)
  std::vector<unsigned char> jpeg_;
};

// Writes `bgr` (CV_8UC3) as a frame file the fake device reads: path.tmp, then rename.
// Returns false if it cannot be written.
bool write_frame_file(const std::string& path, const cv::Mat& bgr);

}  // namespace fake_v4l2
