// Image bytes reach OpenCV's decoders only when they start as an accepted image type.
#include "io/image_file.h"

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/common/test_data.h"

namespace oi = orthoface::io;

namespace {

// A DICOM file cut short: 128 bytes of preamble, then "DICM" (GDCM aborted on it), optionally
// behind a PNG signature.
std::vector<unsigned char> dicom_bytes(const std::string& signature) {
  std::vector<unsigned char> b(128, 0);
  std::copy(signature.begin(), signature.end(), b.begin());
  for (char c : std::string("DICM\0\x02", 6)) b.push_back(static_cast<unsigned char>(c));
  return b;
}

const std::string kPng("\x89PNG\r\n\x1a\n", 8);

}  // namespace

TEST(ImageFile, AcceptsTheSignaturesOfThePhotoTypesOnly) {
  cv::Mat photo(24, 32, CV_8UC3, cv::Scalar(10, 100, 200));
  for (const char* ext : {".png", ".jpg", ".bmp", ".tif", ".webp", ".ppm"}) {
    std::vector<unsigned char> bytes;
    ASSERT_TRUE(cv::imencode(ext, photo, bytes)) << ext;
    EXPECT_TRUE(oi::accepted_image_bytes(bytes.data(), bytes.size())) << ext;
    EXPECT_EQ(oi::imdecode_accepted(cv::Mat(bytes), cv::IMREAD_COLOR).size(), photo.size()) << ext;
  }
  for (const std::string& sig : {std::string(), std::string("\x89PNG\x05\n\x1a\n", 8), kPng}) {
    const std::vector<unsigned char> b = dicom_bytes(sig);
    EXPECT_FALSE(oi::accepted_image_bytes(b.data(), b.size())) << sig.size();
    EXPECT_TRUE(oi::imdecode_accepted(cv::Mat(b), cv::IMREAD_COLOR).empty());
  }
  const std::string text = "P7 not a portable map";
  EXPECT_FALSE(
      oi::accepted_image_bytes(reinterpret_cast<const unsigned char*>(text.data()), text.size()));
  EXPECT_FALSE(oi::accepted_image_bytes(nullptr, 0));
  EXPECT_TRUE(oi::imdecode_accepted(cv::Mat(), cv::IMREAD_COLOR).empty());
  EXPECT_TRUE(oi::imdecode_accepted(cv::Mat(1, 8, CV_32F), cv::IMREAD_COLOR).empty());
}

TEST(ImageFile, ReadsAcceptedFilesAndNothingElse) {
  const auto dir = orthoface::testing::temp_dir("image_file_read");
  const std::string png = (dir / "a.png").string(), dicom = (dir / "b.png").string();
  ASSERT_TRUE(cv::imwrite(png, cv::Mat(24, 32, CV_8UC3, cv::Scalar(1, 2, 3))));
  const std::vector<unsigned char> b = dicom_bytes(kPng);
  std::ofstream(dicom, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), b.size());
  EXPECT_TRUE(oi::accepted_image_file(png));
  EXPECT_EQ(oi::imread_accepted(png, cv::IMREAD_COLOR).cols, 32);
  EXPECT_FALSE(oi::accepted_image_file(dicom));
  EXPECT_TRUE(oi::imread_accepted(dicom, cv::IMREAD_COLOR).empty());
  EXPECT_FALSE(oi::accepted_image_file((dir / "missing.png").string()));
  EXPECT_TRUE(oi::imread_accepted((dir / "missing.png").string(), cv::IMREAD_COLOR).empty());
}
