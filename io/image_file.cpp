#include "io/image_file.h"

#include <algorithm>
#include <cstring>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

namespace orthoface::io {

bool accepted_image_bytes(const unsigned char* bytes, std::size_t size) {
  const auto starts = [&](std::size_t at, const char* sig, std::size_t n) {
    return size >= at + n && std::memcmp(bytes + at, sig, n) == 0;
  };
  const bool jpeg = starts(0, "\xFF\xD8", 2);
  const bool png = starts(0, "\x89PNG\r\n\x1a\n", 8);
  const bool bmp = starts(0, "BM", 2);
  const bool tiff = starts(0, "II*\0", 4) || starts(0, "MM\0*", 4);
  const bool webp = starts(0, "RIFF", 4) && starts(8, "WEBP", 4);
  const bool pnm = size >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6';
  return (jpeg || png || bmp || tiff || webp || pnm) && !starts(128, "DICM", 4);
}

bool accepted_image_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  unsigned char head[132] = {};
  f.read(reinterpret_cast<char*>(head), sizeof head);
  return accepted_image_bytes(head, std::size_t(std::max<std::streamsize>(0, f.gcount())));
}

cv::Mat imread_accepted(const std::string& path, int flags) {
  return accepted_image_file(path) ? cv::imread(path, flags) : cv::Mat();
}

cv::Mat imdecode_accepted(const cv::Mat& buffer, int flags) {
  if (buffer.empty() || !buffer.isContinuous() || buffer.depth() != CV_8U) return {};
  const std::size_t n = buffer.total() * buffer.elemSize();
  return accepted_image_bytes(buffer.ptr(), n) ? cv::imdecode(buffer, flags) : cv::Mat();
}

}  // namespace orthoface::io
