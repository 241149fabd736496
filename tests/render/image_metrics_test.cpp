// PSNR / SSIM against known values.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/core.hpp>

#include "render/image_metrics.h"

namespace orthoface::render {
namespace {

TEST(ImageMetrics, IdenticalImagesGiveInfinityAndOne) {
  cv::Mat a(60, 80, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  EXPECT_TRUE(std::isinf(psnr(a, a)));
  EXPECT_NEAR(ssim(a, a), 1.0, 1e-12);
}

TEST(ImageMetrics, GaussianNoiseGivesTheExpectedPsnr) {
  const cv::Mat a(200, 200, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::Mat noise(a.size(), CV_64FC3), b;
  cv::RNG rng(11);
  rng.fill(noise, cv::RNG::NORMAL, 0, 5.0);
  a.convertTo(b, CV_64F);
  b += noise;
  b.convertTo(b, CV_8U);  // rounding adds 1/12 to the variance
  EXPECT_NEAR(psnr(a, b), 10 * std::log10(255.0 * 255 / (25 + 1.0 / 12)), 0.15);
}

TEST(ImageMetrics, MaskRestrictsTheComparison) {
  cv::Mat a(50, 50, CV_8UC1, cv::Scalar(100)), b = a.clone();
  b(cv::Rect(0, 0, 25, 50)).setTo(200);  // left half differs
  cv::Mat right(a.size(), CV_8U, cv::Scalar(0));
  right(cv::Rect(25, 0, 25, 50)).setTo(255);
  EXPECT_TRUE(std::isinf(psnr(a, b, right)));
  EXPECT_NEAR(psnr(a, b), 10 * std::log10(255.0 * 255 / (100.0 * 100 / 2)), 1e-9);
  EXPECT_LT(ssim(a, b), 0.9);
}

TEST(ImageMetrics, SsimOfAConstantShiftMatchesTheFormula) {
  const cv::Mat a(40, 40, CV_8UC1, cv::Scalar(100)), b(40, 40, CV_8UC1, cv::Scalar(110));
  const double c1 = std::pow(0.01 * 255, 2);
  // Flat images: contrast / structure terms are C2 / C2 = 1, luminance term remains.
  EXPECT_NEAR(ssim(a, b), (2 * 100.0 * 110 + c1) / (100.0 * 100 + 110.0 * 110 + c1), 1e-9);
}

TEST(ImageMetrics, BadInputsThrow) {
  const cv::Mat a(10, 10, CV_8UC3, cv::Scalar::all(0)), b(10, 12, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(psnr(a, b), std::invalid_argument);
  EXPECT_THROW(ssim(a, cv::Mat()), std::invalid_argument);
  EXPECT_THROW(psnr(a, a, cv::Mat(10, 10, CV_8U, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(psnr(a, a, cv::Mat(5, 5, CV_8U, cv::Scalar(255))), std::invalid_argument);
  const cv::Mat f(10, 10, CV_32FC3, cv::Scalar::all(0));
  EXPECT_THROW(ssim(f, f), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
