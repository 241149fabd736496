#include "vision/face_descriptor.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/common/test_data.h"

namespace orthoface::vision {
namespace {

// A fixed 150 x 150 input (no padding or resizing on the way in): R = (3x + 5y) mod 256,
// G = (7x xor 2y) mod 256, B = xy mod 256.
cv::Mat pattern() {
  cv::Mat bgr(150, 150, CV_8UC3);
  for (int y = 0; y < 150; ++y)
    for (int x = 0; x < 150; ++x)
      bgr.at<cv::Vec3b>(y, x) =
          cv::Vec3b((x * y) % 256, ((7 * x) ^ (2 * y)) % 256, (3 * x + 5 * y) % 256);
  return bgr;
}

// face-api.js 1.7.15's own FaceRecognitionNet.computeFaceDescriptor on pattern() (tfjs 4.22,
// WebAssembly backend), to six decimals.
const float kOriginal[128] = {
    -0.019750, 0.113747,  0.050228,  -0.009143, -0.074117, -0.014178, -0.040152, 0.015097,
    0.099872,  -0.031165, 0.188896,  -0.033121, -0.283179, -0.020124, 0.006536,  0.061745,
    -0.125467, -0.025425, -0.185623, -0.115562, 0.052768,  0.022584,  -0.024765, -0.003452,
    -0.105822, -0.274239, -0.039785, -0.067723, 0.088432,  -0.158577, 0.013664,  0.007742,
    -0.155697, -0.053399, -0.024004, 0.041000,  -0.009861, -0.098134, 0.130963,  -0.037148,
    -0.125762, -0.037423, -0.007127, 0.227844,  0.172714,  0.041967,  -0.000146, -0.066730,
    0.071852,  -0.282449, 0.033260,  0.170865,  0.055748,  0.122875,  0.084153,  -0.147424,
    0.038377,  0.105367,  -0.146683, 0.038714,  0.014722,  -0.104918, -0.030989, -0.141181,
    0.177682,  0.052079,  -0.086482, -0.104185, 0.122079,  -0.160962, -0.019760, 0.093703,
    -0.070718, -0.146292, -0.270587, 0.078488,  0.376403,  0.217658,  -0.169487, -0.005374,
    -0.117247, -0.056423, 0.047774,  0.024740,  -0.071240, -0.025844, -0.072924, 0.115183,
    0.179386,  -0.070661, 0.013944,  0.193247,  -0.009727, 0.007254,  -0.022682, 0.002349,
    -0.120596, -0.001398, -0.037189, 0.011895,  0.149573,  -0.146444, 0.039238,  0.101589,
    -0.153173, 0.122670,  0.002585,  -0.032492, 0.083166,  -0.017647, -0.071236, -0.038185,
    0.237798,  -0.228692, 0.211303,  0.198599,  0.024439,  0.110896,  0.022062,  0.143864,
    -0.038930, -0.053389, -0.141016, -0.056046, 0.004036,  -0.016034, -0.019465, -0.005049};

// The weights are fetched, not shipped (scripts/fetch-face-model.sh): without them the tests that
// run the network skip.
#define REQUIRE_WEIGHTS()                                                      \
  if (!shared_describer())                                                     \
    GTEST_SKIP() << "no face_recognition_model.bin in " << default_model_dir() \
                 << " (scripts/fetch-face-model.sh)";

TEST(FaceDescriptor, MatchesTheOriginalNetworkOnAFixedInput) {
  REQUIRE_WEIGHTS();
  const FaceDescriber& net = *shared_describer();
  const FaceDescriptor d = net.describe_crop(pattern());
  double worst = 0;
  for (int k = 0; k < 128; ++k) worst = std::max(worst, double(std::abs(d[k] - kOriginal[k])));
  EXPECT_LT(worst, 2e-5);
}

TEST(FaceDescriptor, ADifferentSizeOfTheSameImageGivesNearlyTheSameDescriptor) {
  REQUIRE_WEIGHTS();
  const FaceDescriber& net = *shared_describer();
  cv::Mat big, other;
  cv::resize(pattern(), big, {300, 300}, 0, 0, cv::INTER_NEAREST);
  cv::flip(pattern(), other, 0);
  const FaceDescriptor a = net.describe_crop(pattern());
  EXPECT_LT(descriptor_distance(a, net.describe_crop(big)), 0.02);
  EXPECT_GT(descriptor_distance(a, net.describe_crop(other)), 0.1);
  // A crop that is not square is padded about its centre: the same as padding it by hand.
  const cv::Mat tall = pattern()(cv::Rect(0, 0, 120, 150));
  cv::Mat padded;
  cv::copyMakeBorder(tall, padded, 0, 0, 15, 15, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  EXPECT_LT(descriptor_distance(net.describe_crop(tall), net.describe_crop(padded)), 1e-6);
}

TEST(FaceDescriptor, CropFollowsDlibsAlignment) {
  std::array<cv::Point2d, 68> p;
  for (auto& q : p) q = {0, 0};
  for (int k = 36; k < 42; ++k) p[k] = {100, 100};  // one eye
  for (int k = 42; k < 48; ++k) p[k] = {160, 100};  // the other
  for (int k = 48; k < 68; ++k) p[k] = {130, 140};  // the mouth
  // Eye-to-mouth 50 px: side floor(50 / 0.45) = 111, centre (130, 113.3).
  const cv::Rect r = face_descriptor_crop(p, {640, 480});
  EXPECT_EQ(r, cv::Rect(74, 65, 111, 111));
  EXPECT_EQ(face_descriptor_crop(p, {150, 150}), cv::Rect(74, 65, 76, 85));  // clipped
  EXPECT_TRUE(face_descriptor_crop(p, {50, 50}).empty());                    // outside
}

TEST(FaceDescriptor, BadInputIsRefused) {
  EXPECT_THROW(FaceDescriber("/nonexistent"), std::runtime_error);
  const auto dir = testing::temp_dir("face_descriptor_broken");
  std::filesystem::copy(default_model_dir() + "/face_recognition_model-weights_manifest.json", dir);
  std::ofstream(dir / "face_recognition_model.bin") << "short";
  try {
    FaceDescriber net(dir.string());
    FAIL() << "a truncated weight file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("face_recognition_model.bin"), std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(dir);
  REQUIRE_WEIGHTS();
  const FaceDescriber& net = *shared_describer();
  EXPECT_THROW(net.describe_crop(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(net.describe_crop(cv::Mat(50, 50, CV_8UC1)), std::invalid_argument);
  std::array<cv::Point2d, 68> p;
  for (auto& q : p) q = {20, 20};
  const cv::Mat grey(100, 100, CV_8UC3, cv::Scalar::all(90));
  EXPECT_THROW(net.describe(grey, p), std::invalid_argument);  // all points in one: no crop
  p[0].x = NAN;
  EXPECT_THROW(net.describe(grey, p), std::invalid_argument);
  EXPECT_THROW(net.describe(cv::Mat(), p), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::vision
