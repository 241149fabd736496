#include "render/contact_sheet.h"

#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tests/common/test_data.h"

namespace orthoface::render {
namespace {

cv::Mat solid(int w, int h, cv::Scalar bgr) { return cv::Mat(h, w, CV_8UC3, bgr); }

// Bounding box of the pixels equal to `bgr`.
cv::Rect find_colour(const cv::Mat& img, cv::Scalar bgr) {
  cv::Mat m;
  cv::inRange(img, bgr, bgr, m);
  return cv::boundingRect(m);
}

TEST(ContactSheet, LaysOutTilesRowByRowWithLabels) {
  ContactSheetOptions o;
  o.columns = 2;
  o.margin_px = 10;
  const std::vector<Tile> tiles = {{solid(100, 80, {255, 0, 0}), "blue"},
                                   {solid(100, 80, {0, 255, 0}), "green"},
                                   {solid(100, 80, {0, 0, 255}), "red"}};
  const cv::Mat sheet = contact_sheet(tiles, o);
  ASSERT_EQ(sheet.type(), CV_8UC3);
  EXPECT_EQ(sheet.cols, 2 * (100 + 10) + 10);
  const cv::Rect b = find_colour(sheet, {255, 0, 0}), g = find_colour(sheet, {0, 255, 0}),
                 r = find_colour(sheet, {0, 0, 255});
  EXPECT_EQ(b, cv::Rect(10, 10, 100, 80));
  EXPECT_EQ(g, cv::Rect(120, 10, 100, 80));
  EXPECT_EQ(r.x, 10);  // third tile starts the second row
  EXPECT_GT(r.y, 90 + 10);
  EXPECT_EQ(r.size(), cv::Size(100, 80));
  // The label band under the first tile holds dark text pixels; the band is otherwise white.
  const cv::Mat band = sheet(cv::Rect(10, 90, 100, r.y - 90 - 10));
  cv::Mat grey;
  cv::cvtColor(band, grey, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(grey < 128), 10);
}

TEST(ContactSheet, ScalesTilesIntoTheCellKeepingAspectAndAcceptsGrey) {
  ContactSheetOptions o;
  o.tile_width = 50;
  o.tile_height = 50;
  o.margin_px = 0;
  o.title = "Title";
  cv::Mat grey(40, 200, CV_8U, cv::Scalar(0));
  const cv::Mat sheet = contact_sheet({{grey, ""}}, o);
  const cv::Rect box = find_colour(sheet, {0, 0, 0});
  // 200x40 scaled into 50x50 -> 50x10, centred vertically in the cell below the title.
  EXPECT_EQ(box.width, 50);
  EXPECT_NEAR(box.height, 10, 1);
  EXPECT_GT(box.y, 20);
}

TEST(ContactSheet, EmptyTileLeavesABlankLabelledCell) {
  const cv::Mat sheet = contact_sheet({{cv::Mat(), "missing"}, {solid(30, 30, {0, 0, 0}), "x"}});
  EXPECT_EQ(find_colour(sheet, {0, 0, 0}).x, 8 + 30 + 8);
  const cv::Mat one = contact_sheet({{cv::Mat(), "only"}});  // degenerate: nothing to show
  EXPECT_FALSE(one.empty());
}

TEST(ContactSheet, RejectsBadInput) {
  EXPECT_THROW(contact_sheet({}), std::invalid_argument);
  EXPECT_THROW(contact_sheet({{cv::Mat(10, 10, CV_32F), "float"}}), std::invalid_argument);
  ContactSheetOptions o;
  o.columns = -1;
  EXPECT_THROW(contact_sheet({{solid(4, 4, {}), ""}}, o), std::invalid_argument);
  o = {};
  o.font_scale = 0;
  EXPECT_THROW(contact_sheet({{solid(4, 4, {}), ""}}, o), std::invalid_argument);
  EXPECT_THROW(contact_sheet(std::vector<Tile>(400, {solid(100, 100, {}), ""})),
               std::invalid_argument);  // 400 tiles in one row: too wide
}

TEST(WritePng, WritesViaTmpAndFailsOnBadPath) {
  const auto dir = testing::temp_dir("contact_sheet_png");
  const std::string path = (dir / "sheet.png").string();
  write_png(solid(7, 5, {1, 2, 3}), path);
  const cv::Mat back = cv::imread(path);
  ASSERT_EQ(back.size(), cv::Size(7, 5));
  EXPECT_EQ(back.at<cv::Vec3b>(0, 0), cv::Vec3b(1, 2, 3));
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_THROW(write_png(solid(2, 2, {}), (dir / "no" / "x.png").string()), std::runtime_error);
  EXPECT_THROW(write_png(cv::Mat(), path), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::render
