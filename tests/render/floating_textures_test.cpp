// Floating textures: two renderings that disagree by a known shift blend into one image.
#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "render/floating_textures.h"
#include "render/image_metrics.h"

namespace orthoface::render {
namespace {

constexpr int kW = 240, kH = 160;

// A smooth random texture with a dark disc, translated by dx pixels.
cv::Mat scene(double dx) {
  cv::Mat noise(kH / 4, kW / 4 + 20, CV_8UC3);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::UNIFORM, 40, 220);
  cv::Mat big;
  cv::resize(noise, big, cv::Size(4 * noise.cols, 4 * noise.rows), 0, 0, cv::INTER_CUBIC);
  cv::GaussianBlur(big, big, cv::Size(0, 0), 2.0);
  cv::circle(big, cv::Point(120, 80), 14, cv::Scalar(10, 10, 10), cv::FILLED, cv::LINE_AA);
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, dx + 10, 0, 1, 0);
  cv::Mat out;
  cv::warpAffine(big, out, shift, cv::Size(kW, kH), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

// The seam case: the front photo's share is 1 left of x = 120, the side photo's right of it.
FloatInputs seam_inputs(const cv::Mat& a, const cv::Mat& b, double alpha) {
  FloatInputs in;
  in.source[0] = a;
  in.source[1] = b;
  in.available[0] = cv::Mat(kH, kW, CV_8U, cv::Scalar(255));
  in.available[1] = in.available[0].clone();
  in.weights = cv::Mat(kH, kW, CV_8UC3, cv::Scalar(255, 0, 0));
  in.weights(cv::Rect(kW / 2, 0, kW / 2, kH)).setTo(cv::Scalar(0, 255, 0));
  in.mask = cv::Mat(kH, kW, CV_8U, cv::Scalar(255));
  in.alpha = alpha;
  return in;
}

cv::Mat pick(const FloatInputs& in) {
  cv::Mat out = in.source[0].clone();
  in.source[1](cv::Rect(kW / 2, 0, kW / 2, kH)).copyTo(out(cv::Rect(kW / 2, 0, kW / 2, kH)));
  return out;
}

TEST(FloatingTextures, AlignsTwoShiftedRenderingsAtTheAlphaPosition) {
  const cv::Mat a = scene(0), b = scene(16), half = scene(8);
  const FloatInputs in = seam_inputs(a, b, 0.5);
  const cv::Mat base = pick(in);
  const FloatResult r = float_textures(in, base);
  const cv::Rect inner(24, 16, kW - 48, kH - 32);  // away from the replicated borders
  const double aligned = psnr(half(inner), r.image(inner));
  const double seam = psnr(half(inner), base(inner));
  EXPECT_GT(aligned, 28.0);
  EXPECT_GT(aligned, seam + 8.0) << "seam " << seam;
  EXPECT_NEAR(r.mean_shift_px, 16.0, 2.0);
  EXPECT_EQ(r.overlap_pixels, kW * kH);
}

TEST(FloatingTextures, AlphaZeroKeepsTheFrontRenderingUnmoved) {
  const cv::Mat a = scene(0), b = scene(12);
  const FloatInputs in = seam_inputs(a, b, 0.0);  // the front camera's own view: per pixel
  const FloatResult r = float_textures(in, pick(in));
  const cv::Rect left(0, 0, kW / 2, kH);  // the front photo's share: not warped at all
  EXPECT_TRUE(std::isinf(psnr(a(left), r.image(left))));
  const cv::Rect right(kW / 2, 16, kW / 2 - 24, kH - 32);  // the side's, moved onto the front's
  EXPECT_GT(psnr(a(right), r.image(right)), 28.0);
}

// The side photo 40 grey levels brighter than the front, aligned: per pixel the blend steps by
// 40 at the seam; band by band the step fades out and the texture stays as sharp as it was.
TEST(FloatingTextures, ABrightnessStepBetweenThePhotosLeavesNoSeam) {
  const cv::Mat a = scene(0), b = a + cv::Scalar::all(40);
  auto blend = [&](int bands) {
    FloatInputs in = seam_inputs(a, b, 0.5);
    in.bands = bands;
    return float_textures(in, pick(in)).image;
  };
  // The step across the seam beyond the texture's own, mean over rows (grey levels).
  auto step = [&](const cv::Mat& image) {
    double sum = 0;
    for (int y = 0; y < kH; ++y) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, kW / 2), q = image.at<cv::Vec3b>(y, kW / 2 - 1);
      const cv::Vec3b s = a.at<cv::Vec3b>(y, kW / 2), t = a.at<cv::Vec3b>(y, kW / 2 - 1);
      sum += double(p[1]) - q[1] - (double(s[1]) - t[1]);
    }
    return sum / kH;
  };
  // Detail: the image less its blur (sigma 1.5 px) against the source's, each side of the seam.
  auto detail = [](const cv::Mat& image) {
    cv::Mat f, blurred;
    image.convertTo(f, CV_32FC3);
    cv::GaussianBlur(f, blurred, cv::Size(0, 0), 1.5);
    return cv::Mat(f - blurred);
  };
  const cv::Mat per_pixel = blend(1), banded = blend(6);
  EXPECT_NEAR(step(per_pixel), 40.0, 2.0);
  EXPECT_LT(std::abs(step(banded)), 6.0);
  const cv::Mat d = detail(banded), da = detail(a), db = detail(b);
  const cv::Rect left(8, 8, kW / 2 - 24, kH - 16), right(kW / 2 + 16, 8, kW / 2 - 24, kH - 16);
  EXPECT_LT(cv::norm(d(left), da(left), cv::NORM_INF), 4.0);
  EXPECT_LT(cv::norm(d(right), db(right), cv::NORM_INF), 4.0);
}

// An eye shut in one photo and open in the other: a dark ellipse in the front photo alone, where
// the front photo's share is 1. No flow can match it, so none may move it: it stays as the front
// photo shows it, not smeared toward whatever the flow found in the side photo.
TEST(FloatingTextures, AFeatureInOnePhotoAloneStaysWhereThatPhotoHasIt) {
  const cv::Mat b = scene(0);
  cv::Mat a = b.clone();
  cv::ellipse(a, cv::Point(48, 80), cv::Size(18, 7), 0, 0, 360, cv::Scalar(20, 15, 10), cv::FILLED,
              cv::LINE_AA);
  FloatInputs in = seam_inputs(a, b, 0.5);
  const FloatResult r = float_textures(in, pick(in));
  const cv::Rect eye(24, 64, 48, 32);
  EXPECT_GT(psnr(a(eye), r.image(eye)), 35.0);
  // The raw flow (the identity check's choice) drags the eye into the skin around it.
  in.round_trip = false;
  const FloatResult raw = float_textures(in, pick(in));
  EXPECT_LT(psnr(a(eye), raw.image(eye)), 25.0);
}

TEST(FloatingTextures, LeavesTheBackgroundAndUnseenPixelsToTheBase) {
  const cv::Mat a = scene(0), b = scene(10);
  FloatInputs in = seam_inputs(a, b, 0.5);
  in.mask(cv::Rect(0, 0, 20, kH)).setTo(0);
  cv::Mat base = pick(in);
  base(cv::Rect(0, 0, 20, kH)).setTo(cv::Scalar(1, 2, 3));
  in.weights(cv::Rect(200, 0, 40, kH)).setTo(cv::Scalar(0, 0, 255));  // no photo sees these
  in.fill = cv::Vec3b(7, 8, 9);
  const FloatResult r = float_textures(in, base);
  EXPECT_EQ(r.image.at<cv::Vec3b>(50, 5), cv::Vec3b(1, 2, 3));
  EXPECT_EQ(r.image.at<cv::Vec3b>(50, 220), cv::Vec3b(7, 8, 9));
}

TEST(FloatingTextures, RejectsBadInputNamingIt) {
  const cv::Mat a = scene(0);
  const FloatInputs good = seam_inputs(a, a, 0.5);
  auto message = [&](FloatInputs in, const cv::Mat& base) {
    try {
      float_textures(in, base);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  FloatInputs in = good;
  in.source[1] = cv::Mat(10, 10, CV_8UC3);
  EXPECT_NE(message(in, a).find("side source image"), std::string::npos);
  in = good;
  in.available[0] = cv::Mat(kH, kW, CV_32F);
  EXPECT_NE(message(in, a).find("front availability"), std::string::npos);
  in = good;
  in.weights = cv::Mat();
  EXPECT_NE(message(in, a).find("weights"), std::string::npos);
  in = good;
  in.alpha = 1.5;
  EXPECT_NE(message(in, a).find("alpha"), std::string::npos);
  in = good;
  in.alpha = NAN;
  EXPECT_NE(message(in, a).find("alpha"), std::string::npos);
  in = good;
  in.bands = 0;
  EXPECT_NE(message(in, a).find("bands"), std::string::npos);
  EXPECT_NE(message(good, cv::Mat(kH, kW, CV_8U)).find("rendered view"), std::string::npos);
}

TEST(FloatingTextures, AlphaIsTheShareOfTheAngleToTheFrontCamera) {
  const cv::Vec3d front(0, 0, 1), side(1, 0, 0);
  EXPECT_NEAR(float_alpha(front, front, side), 0.0, 1e-12);
  EXPECT_NEAR(float_alpha(side, front, side), 1.0, 1e-12);
  EXPECT_NEAR(float_alpha(cv::Vec3d(1, 0, 1), front, side), 0.5, 1e-12);
  EXPECT_NEAR(float_alpha(cv::Vec3d(-1, 0, 1), front, side), 0.25, 1e-12);  // the other side
  EXPECT_THROW(float_alpha(cv::Vec3d(0, 0, 0), front, side), std::invalid_argument);
  EXPECT_THROW(float_alpha(front, cv::Vec3d(NAN, 0, 1), side), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
