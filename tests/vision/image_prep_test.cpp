// Photos as 8-bit BGR whatever they were stored as, and unreadable files.
#include "vision/image_prep.h"

#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

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

TEST(ImagePrep, OnlyPhotoFormatsReachTheDecoders) {
  const auto dir = orthoface::testing::temp_dir("image_prep_formats");
  // 128 bytes then "DICM": a DICOM file, cut short. OpenCV hands it to GDCM, which aborted.
  std::string dicom(128, '\0');
  dicom.replace(0, 5, "G\r\n.\x1a", 5);
  dicom += std::string("DICM\0", 5);
  const std::string bad = (dir / "scan.png").string();
  // The same behind a PNG signature that is one byte wrong, and behind a correct one.
  std::string near_png = dicom, png = dicom;
  near_png.replace(0, 8, "\x89PNG\x05\n\x1a\n", 8);
  png.replace(0, 8, "\x89PNG\r\n\x1a\n", 8);
  for (const std::string& bytes : {dicom, near_png, png}) {
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << bytes;
    try {
      ov::read_image(bad);
      ADD_FAILURE() << "a DICOM file was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("scan.png"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("not a PNG, JPEG"), std::string::npos) << e.what();
    }
  }
  // Every format the tools accept still reads.
  const cv::Mat photo(48, 64, CV_8UC3, cv::Scalar(30, 120, 200));
  for (const char* ext : {".png", ".jpg", ".bmp", ".tif", ".webp", ".ppm", ".pgm"}) {
    const std::string path = (dir / (std::string("photo") + ext)).string();
    const bool grey = std::string(ext) == ".pgm";
    ASSERT_TRUE(cv::imwrite(path, grey ? cv::Mat(photo.size(), CV_8U, cv::Scalar(90)) : photo))
        << ext;
    EXPECT_EQ(ov::read_image(path).size(), photo.size()) << ext;
  }
}
