#include "frame_source.h"

#include <linux/videodev2.h>

#include <cstdio>
#include <cstring>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fake_v4l2 {
namespace {

cv::Mat read_frame_file(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return {};
  char magic[4];
  int size[2];
  cv::Mat m;
  if (std::fread(magic, 1, 4, f) == 4 && !std::memcmp(magic, "OFV1", 4) &&
      std::fread(size, sizeof(int), 2, f) == 2 && size[0] > 0 && size[1] > 0 && size[0] <= 8192 &&
      size[1] <= 8192) {
    m.create(size[1], size[0], CV_8UC3);
    if (std::fread(m.data, 1, m.total() * 3, f) != m.total() * 3) m.release();
  }
  std::fclose(f);
  return m;
}

cv::Mat test_pattern(int width, int height, unsigned sequence) {
  cv::Mat m(height, width, CV_8UC3);
  static const cv::Scalar bars[] = {{255, 255, 255}, {0, 255, 255}, {255, 255, 0}, {0, 255, 0},
                                    {255, 0, 255},   {0, 0, 255},   {255, 0, 0},   {0, 0, 0}};
  for (int i = 0; i < 8; ++i)
    m(cv::Rect(i * width / 8, 0, (i + 1) * width / 8 - i * width / 8, height)).setTo(bars[i]);
  const int s = height / 6, x = int(sequence * 4 % unsigned(width - s));
  cv::rectangle(m, cv::Rect(x, height / 2 - s / 2, s, s), cv::Scalar(40, 40, 40), cv::FILLED);
  cv::putText(m, std::to_string(sequence), {8, height - 12}, cv::FONT_HERSHEY_SIMPLEX, 1.0,
              cv::Scalar(0, 0, 0), 2);
  return m;
}

void to_yuyv(const cv::Mat& bgr, unsigned char* dst) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);  // full-range BT.601, as OpenCV's YUYV decoder
  for (int r = 0; r < yuv.rows; ++r) {
    const cv::Vec3b* p = yuv.ptr<cv::Vec3b>(r);
    unsigned char* d = dst + size_t(r) * yuv.cols * 2;
    for (int c = 0; c + 1 < yuv.cols; c += 2) {
      d[2 * c] = p[c][0];
      d[2 * c + 1] = static_cast<unsigned char>((p[c][1] + p[c + 1][1]) / 2);
      d[2 * c + 2] = p[c + 1][0];
      d[2 * c + 3] = static_cast<unsigned char>((p[c][2] + p[c + 1][2]) / 2);
    }
  }
}

}  // namespace

cv::Mat FrameSource::next_bgr(int width, int height, unsigned sequence) {
  if (file_.empty()) return test_pattern(width, height, sequence);
  cv::Mat m = read_frame_file(file_);
  if (!m.empty()) last_ = m;
  if (last_.empty()) return test_pattern(width, height, sequence);  // feeder not started yet
  if (last_.cols == width && last_.rows == height) return last_;
  cv::Mat resized;
  cv::resize(last_, resized, {width, height}, 0, 0, cv::INTER_AREA);
  return resized;
}

size_t FrameSource::fill(unsigned pixelformat, int width, int height, unsigned sequence,
                         unsigned char* dst, size_t capacity) {
  const cv::Mat bgr = next_bgr(width, height, sequence);
  if (pixelformat == V4L2_PIX_FMT_YUYV) {
    const size_t n = size_t(width) * height * 2;
    if (n > capacity) return 0;
    to_yuyv(bgr, dst);
    return n;
  }
  cv::imencode(".jpg", bgr, jpeg_, {cv::IMWRITE_JPEG_QUALITY, 85});
  if (jpeg_.size() > capacity) return 0;
  std::memcpy(dst, jpeg_.data(), jpeg_.size());
  return jpeg_.size();
}

bool write_frame_file(const std::string& path, const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) return false;
  const std::string tmp = path + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) return false;
  const int size[2] = {bgr.cols, bgr.rows};
  bool ok = std::fwrite("OFV1", 1, 4, f) == 4 && std::fwrite(size, sizeof(int), 2, f) == 2;
  const cv::Mat c = bgr.isContinuous() ? bgr : bgr.clone();
  ok = ok && std::fwrite(c.data, 1, c.total() * 3, f) == c.total() * 3;
  ok = std::fclose(f) == 0 && ok;
  return ok && std::rename(tmp.c_str(), path.c_str()) == 0;
}

}  // namespace fake_v4l2
