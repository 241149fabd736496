#include "render/contact_sheet.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/atomic_file.h"

namespace orthoface::render {
namespace {

constexpr int kMaxSheetSide = 16384;
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

cv::Mat to_bgr(const cv::Mat& image, size_t index) {
  if (image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw std::invalid_argument("contact_sheet: tile " + std::to_string(index) +
                                " must be 8-bit grey, BGR or BGRA, got type " +
                                std::to_string(image.type()));
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4)
    cv::cvtColor(image, out, cv::COLOR_BGRA2BGR);
  else
    out = image;
  return out;
}

// Shortens `text` with "..." until it fits `width` pixels at `scale`.
std::string fit_text(std::string text, int width, double scale) {
  int base = 0;
  auto w = [&](const std::string& t) { return cv::getTextSize(t, kFont, scale, 1, &base).width; };
  if (w(text) <= width) return text;
  while (!text.empty() && w(text + "...") > width) text.pop_back();
  return text.empty() ? std::string() : text + "...";
}

int text_height(double scale) {
  int base = 0;
  const cv::Size s = cv::getTextSize("Ag", kFont, scale, 1, &base);
  return s.height + base;
}

// `image` scaled to fit `cell` keeping its aspect, centred on `sheet` at `cell_origin`.
void place(cv::Mat& sheet, const cv::Mat& image, cv::Point cell_origin, cv::Size cell) {
  const double s = std::min(cell.width / double(image.cols), cell.height / double(image.rows));
  const cv::Size size(std::max(1, int(std::lround(image.cols * s))),
                      std::max(1, int(std::lround(image.rows * s))));
  cv::Mat scaled;
  if (size == image.size())
    scaled = image;
  else
    cv::resize(image, scaled, size, 0, 0, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  const cv::Point at =
      cell_origin + cv::Point((cell.width - size.width) / 2, (cell.height - size.height) / 2);
  scaled.copyTo(sheet(cv::Rect(at, size)));
}

}  // namespace

void ContactSheetOptions::check() const {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("ContactSheetOptions: " + what);
  };
  if (columns < 0) bad("columns must be >= 0");
  if (tile_width < 0 || tile_height < 0 || tile_width > kMaxSheetSide ||
      tile_height > kMaxSheetSide)
    bad("tile size must be in 0..16384");
  if (margin_px < 0 || margin_px > 1000) bad("margin_px must be in 0..1000");
  if (!std::isfinite(font_scale) || font_scale <= 0 || font_scale > 10)
    bad("font_scale must be in (0, 10]");
}

cv::Mat contact_sheet(const std::vector<Tile>& tiles, const ContactSheetOptions& options) {
  options.check();
  if (tiles.empty()) throw std::invalid_argument("contact_sheet: no tiles");
  std::vector<cv::Mat> images(tiles.size());
  cv::Size cell(options.tile_width, options.tile_height);
  for (size_t i = 0; i < tiles.size(); ++i) {
    if (tiles[i].image.empty()) continue;
    images[i] = to_bgr(tiles[i].image, i);
    if (options.tile_width == 0) cell.width = std::max(cell.width, images[i].cols);
    if (options.tile_height == 0) cell.height = std::max(cell.height, images[i].rows);
  }
  if (cell.width == 0) cell.width = 64;  // every tile empty: blank cells still show labels
  if (cell.height == 0) cell.height = 64;
  const int n = static_cast<int>(tiles.size());
  const int cols = options.columns > 0 ? std::min(options.columns, n) : n;
  const int rows = (n + cols - 1) / cols;
  const int m = options.margin_px, label_h = text_height(options.font_scale) + m / 2 + 2;
  const int title_h = options.title.empty() ? 0 : text_height(options.font_scale * 1.6) + m;
  const long width = long(cols) * (cell.width + m) + m;
  const long height = title_h + long(rows) * (cell.height + label_h + m) + m;
  if (width > kMaxSheetSide || height > kMaxSheetSide)
    throw std::invalid_argument("contact_sheet: sheet of " + std::to_string(width) + "x" +
                                std::to_string(height) + " px exceeds 16384 per side");
  cv::Mat sheet(int(height), int(width), CV_8UC3, options.background);
  if (!options.title.empty())
    cv::putText(sheet, fit_text(options.title, int(width) - 2 * m, options.font_scale * 1.6),
                cv::Point(m, m + text_height(options.font_scale * 1.6) - 2), kFont,
                options.font_scale * 1.6, options.text_bgr, 2, cv::LINE_AA);
  for (int i = 0; i < n; ++i) {
    const cv::Point origin(m + (i % cols) * (cell.width + m),
                           title_h + m + (i / cols) * (cell.height + label_h + m));
    if (!images[i].empty()) place(sheet, images[i], origin, cell);
    const std::string label = fit_text(tiles[i].label, cell.width, options.font_scale);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, kFont, options.font_scale, 1, &base);
    cv::putText(sheet, label,
                origin + cv::Point((cell.width - ts.width) / 2, cell.height + ts.height + m / 2),
                kFont, options.font_scale, options.text_bgr, 1, cv::LINE_AA);
  }
  return sheet;
}

void write_png(const cv::Mat& image, const std::string& path) {
  if (image.empty()) throw std::invalid_argument("write_png: empty image for " + path);
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes))
    throw std::runtime_error("write_png: cannot encode " + path + " as PNG");
  io::write_text_atomically(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace orthoface::render
