#include "io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

namespace orthoface::io {
namespace {

namespace fs = std::filesystem;

void remove_quietly(const std::string& path) {
  std::error_code ec;
  fs::remove(path, ec);
}

}  // namespace

std::string temp_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(path);
  const std::string name = "." + p.filename().string() + ".orthoface-" +
                           std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".tmp" +
                           p.extension().string();
  return (p.parent_path() / name).string();
}

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp)>& write) {
  // The rename would replace whatever is there: a device node, a socket or a folder's link is
  // not a file to overwrite.
  std::error_code st;
  const fs::file_status status = fs::symlink_status(path, st);
  if (!st && fs::exists(status) && !fs::is_regular_file(status))
    throw std::runtime_error("cannot write " + path + ": it exists and is not a regular file");
  const std::string tmp = temp_path_for(path);
  try {
    write(tmp);
  } catch (const std::exception& e) {
    remove_quietly(tmp);
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    remove_quietly(tmp);
    throw std::runtime_error("cannot write " + path + ": " + ec.message());
  }
}

void write_stream_atomically(const std::string& path,
                             const std::function<void(std::ostream& out)>& write) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("cannot open a file in its folder");
    write(out);
    out.close();
    if (!out) throw std::runtime_error("write failed (disk full?)");
  });
}

void write_text_atomically(const std::string& path, const std::string& text) {
  write_stream_atomically(path, [&](std::ostream& out) { out << text; });
}

void write_image_atomically(const std::string& path, const cv::Mat& image) {
  if (image.empty()) throw std::runtime_error("cannot write " + path + ": empty image");
  write_atomically(path, [&](const std::string& tmp) {
    bool ok = false;
    try {
      ok = cv::imwrite(tmp, image);
    } catch (const cv::Exception& e) {
      throw std::runtime_error("cannot encode the image (" + std::string(e.err) + ")");
    }
    if (!ok) throw std::runtime_error("cannot encode or write the image");
  });
}

}  // namespace orthoface::io
