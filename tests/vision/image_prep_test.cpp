// Photos as 8-bit BGR whatever they were stored as, and unreadable files.
#include "vision/image_prep.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "tests/common/test_data.h"

namespace ov = orthoface::vision;

TEST(ImagePrep, ConvertsGreySixteenBitAndAlpha) {
  cv::Mat g16(64, 64, CV_16U, cv::Scalar(1000));
  g16.at<uint16_t>(0, 0) = 4000;
  const cv::Mat a = ov::to_bgr8(g16, "test");
  EXPECT_EQ(a.type(), CV_8UC3);
  EXPECT_NEAR(a.at<cv::Vec3b>(1, 1)[0], 1000 * 255.0 / 4000, 1.0);
  EXPECT_EQ(ov::to_bgr8(cv::Mat(64, 64, CV_8UC4, cv::Scalar(1, 2, 3, 4)), "t").at<cv::Vec3b>(0, 0),
            cv::Vec3b(1, 2, 3));
  EXPECT_THROW(ov::to_bgr8(cv::Mat(), "front image"), std::invalid_argument);
  EXPECT_THROW(ov::to_bgr8(cv::Mat(1, 1, CV_8UC3), "front image"), std::invalid_argument);
  EXPECT_THROW(ov::to_bgr8(cv::Mat(40, 400, CV_8UC3), "front image"), std::invalid_argument);
}

TEST(ImagePrep, BadInputFilesGiveClearErrors) {
  const std::string dir = orthoface::testing::shared_data("bad_inputs");
  if (dir.empty()) GTEST_SKIP() << "no ../shared/data";
  for (const char* f : {"image_empty.jpg", "image_truncated.jpg", "image_text_named_jpg.jpg",
                        "image_1x1.png", "image_wide_20000x8.png", "image_huge_header.png"}) {
    try {
      ov::read_image(dir + "/" + f);
      ADD_FAILURE() << f << " was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(ov::read_image(dir + "/image_gray16.png").type(), CV_8UC3);
  EXPECT_EQ(ov::read_image(dir + "/image_rgba.png").type(), CV_8UC3);
  EXPECT_THROW(ov::read_image(dir + "/no_such_file.png"), std::runtime_error);
}
