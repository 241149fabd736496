#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::render {

// One cell of a contact sheet: an image (8-bit BGR, grey or BGRA) and the text under it.
struct Tile {
  cv::Mat image;
  std::string label;
};

struct ContactSheetOptions {
  int columns = 0;          // tiles per row; 0 = all in one row
  int tile_width = 0;       // cell image size, pixels; 0 = the largest tile's size
  int tile_height = 0;      // (each image is scaled to fit its cell, keeping its aspect ratio)
  int margin_px = 8;        // gap around and between cells
  std::string title;        // optional line across the top
  double font_scale = 0.5;  // label text size (OpenCV Hershey simplex)
  cv::Scalar background{255, 255, 255};  // BGR
  cv::Scalar text_bgr{20, 20, 20};
  // Throws std::invalid_argument naming the first bad field.
  void check() const;
};

// Tiles laid out row by row, each centred in its cell with its label below it, as one CV_8UC3
// image. An empty tile image leaves a blank cell with the label. Throws std::invalid_argument
// when there are no tiles, a tile has an unsupported image type, or the sheet would exceed
// 16384 px per side.
cv::Mat contact_sheet(const std::vector<Tile>& tiles, const ContactSheetOptions& options = {});

// Writes `image` as PNG all or nothing (io::write_text_atomically). Throws std::runtime_error
// naming the path.
void write_png(const cv::Mat& image, const std::string& path);

}  // namespace orthoface::render
