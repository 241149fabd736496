#include "render/image_metrics.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace orthoface::render {
namespace {

// Validates the inputs; returns the mask to use (all-255 when `mask` is empty).
cv::Mat checked_mask(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask,
                     const std::string& what) {
  if (a.empty() || b.empty()) throw std::invalid_argument(what + ": empty image");
  if (a.size() != b.size() || a.type() != b.type())
    throw std::invalid_argument(what + ": images differ in size or type");
  if (a.depth() != CV_8U || (a.channels() != 1 && a.channels() != 3))
    throw std::invalid_argument(what + ": images must be 8-bit grey or BGR");
  if (mask.empty()) return cv::Mat(a.size(), CV_8U, cv::Scalar(255));
  if (mask.size() != a.size() || mask.type() != CV_8U)
    throw std::invalid_argument(what + ": mask must be CV_8U of the image size");
  if (cv::countNonZero(mask) == 0) throw std::invalid_argument(what + ": mask selects no pixel");
  return mask;
}

cv::Mat luma(const cv::Mat& img) {
  cv::Mat g;
  if (img.channels() == 3)
    cv::cvtColor(img, g, cv::COLOR_BGR2GRAY);
  else
    g = img;
  g.convertTo(g, CV_64F);
  return g;
}

}  // namespace

double psnr(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask) {
  const cv::Mat m = checked_mask(reference, test, mask, "psnr");
  cv::Mat a, b;
  reference.convertTo(a, CV_64F);
  test.convertTo(b, CV_64F);
  cv::Mat d = a - b;
  d = d.mul(d);
  const cv::Scalar sum = cv::sum(d.setTo(0, m == 0));
  const double mse = (sum[0] + sum[1] + sum[2]) / (double(cv::countNonZero(m)) * a.channels());
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10 * std::log10(255.0 * 255.0 / mse);
}

double ssim(const cv::Mat& reference, const cv::Mat& test, const cv::Mat& mask) {
  const cv::Mat m = checked_mask(reference, test, mask, "ssim");
  const cv::Mat x = luma(reference), y = luma(test);
  const double c1 = std::pow(0.01 * 255, 2), c2 = std::pow(0.03 * 255, 2);
  auto blur = [](const cv::Mat& in) {
    cv::Mat out;
    cv::GaussianBlur(in, out, cv::Size(11, 11), 1.5, 1.5, cv::BORDER_REFLECT);
    return out;
  };
  const cv::Mat mx = blur(x), my = blur(y);
  const cv::Mat sxx = blur(x.mul(x)) - mx.mul(mx), syy = blur(y.mul(y)) - my.mul(my);
  const cv::Mat sxy = blur(x.mul(y)) - mx.mul(my);
  cv::Mat num = (2 * mx.mul(my) + c1).mul(2 * sxy + c2);
  cv::Mat den = (mx.mul(mx) + my.mul(my) + c1).mul(sxx + syy + c2);
  cv::Mat map;
  cv::divide(num, den, map);
  return cv::mean(map, m)[0];
}

}  // namespace orthoface::render
