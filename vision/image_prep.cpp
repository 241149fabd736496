#include "vision/image_prep.h"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/image_file.h"

namespace orthoface::vision {

namespace {

constexpr int kMinSide = 32;
constexpr int kMaxSide = 20000;

// Scales a 16-bit or float single/multi-channel image to 8 bits by its own range.
cv::Mat to_depth8(const cv::Mat& image) {
  if (image.depth() == CV_8U) return image;
  double lo = 0, hi = 0;
  cv::minMaxLoc(image.reshape(1), &lo, &hi);
  if (!std::isfinite(lo) || !std::isfinite(hi)) throw std::invalid_argument("non-finite pixels");
  double scale = 1.0;
  if (image.depth() == CV_16U || image.depth() == CV_16S)
    scale = hi > 255 ? 255.0 / hi : 1.0;
  else
    scale = hi <= 1.0 ? 255.0 : (hi > 255 ? 255.0 / hi : 1.0);
  cv::Mat out;
  image.convertTo(out, CV_8U, scale);
  return out;
}

// A JPEG must end with its EOI marker and a PNG with its IEND chunk; decoders accept truncated
// files silently and return half-grey images otherwise.
void check_not_truncated(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::string head(8, '\0');
  f.read(head.data(), 8);
  f.seekg(0, std::ios::end);
  const std::streamoff size = f.tellg();
  if (size < 16) return;
  std::string tail(16, '\0');
  f.seekg(size - 16);
  f.read(tail.data(), 16);
  const bool jpeg = uchar(head[0]) == 0xFF && uchar(head[1]) == 0xD8;
  const bool png = head.compare(1, 3, "PNG") == 0;
  const std::string trimmed = tail.substr(0, tail.find_last_not_of('\0') + 1);
  if (jpeg && !(trimmed.size() >= 2 && uchar(trimmed[trimmed.size() - 2]) == 0xFF &&
                uchar(trimmed.back()) == 0xD9))
    throw std::runtime_error("image '" + path + "': truncated JPEG (no end-of-image marker)");
  if (png && tail.find("IEND") == std::string::npos)
    throw std::runtime_error("image '" + path + "': truncated PNG (no IEND chunk)");
}

}  // namespace

cv::Mat read_image(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("image '" + path + "': no such file");
  if (!io::accepted_image_file(path))
    throw std::runtime_error("image '" + path + "': not a " + io::kAcceptedImageTypes + " file");
  check_not_truncated(path);
  cv::Mat raw;
  try {
    raw = cv::imread(path, cv::IMREAD_UNCHANGED);  // accepted above
  } catch (const cv::Exception& e) {
    throw std::runtime_error("image '" + path + "': cannot be decoded (" + e.msg + ")");
  }
  if (raw.empty())
    throw std::runtime_error("image '" + path +
                             "': not a readable image (empty, truncated or "
                             "unsupported format)");
  try {
    return to_bgr8(raw, "image '" + path + "'");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
}

cv::Mat to_bgr8(const cv::Mat& image, const std::string& what) {
  if (image.empty()) throw std::invalid_argument(what + ": empty image");
  if (image.cols < kMinSide || image.rows < kMinSide)
    throw std::invalid_argument(what + ": image " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + " is too small (at least " +
                                std::to_string(kMinSide) + "x" + std::to_string(kMinSide) + ")");
  if (image.cols > kMaxSide || image.rows > kMaxSide)
    throw std::invalid_argument(what + ": image " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + " is too large");
  const double aspect = double(std::max(image.cols, image.rows)) / std::min(image.cols, image.rows);
  if (aspect > 8.0)
    throw std::invalid_argument(what + ": image " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + " has an implausible aspect ratio");
  const int ch = image.channels();
  if (ch != 1 && ch != 3 && ch != 4)
    throw std::invalid_argument(what + ": unsupported channel count " + std::to_string(ch));
  const int d = image.depth();
  if (d != CV_8U && d != CV_16U && d != CV_16S && d != CV_32F && d != CV_64F)
    throw std::invalid_argument(what + ": unsupported pixel depth " + std::to_string(d));
  cv::Mat m8;
  try {
    m8 = to_depth8(image);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": " + e.what());
  }
  cv::Mat out;
  if (ch == 1)
    cv::cvtColor(m8, out, cv::COLOR_GRAY2BGR);
  else if (ch == 4)
    cv::cvtColor(m8, out, cv::COLOR_BGRA2BGR);
  else
    out = m8.clone();
  return out;
}

cv::Mat grey(const cv::Mat& bgr) {
  cv::Mat g;
  cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
  return g;
}

}  // namespace orthoface::vision
