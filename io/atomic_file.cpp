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

// The outermost open group of this thread, or null.
thread_local FileGroup* current_group = nullptr;

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
  } catch (...) {  // not ours to interpret, but the temporary must still go
    remove_quietly(tmp);
    throw;
  }
  if (FileGroup* group = current_group) {
    try {
      group->files_.emplace_back(tmp, path);
    } catch (...) {
      remove_quietly(tmp);
      throw;
    }
    return;
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
    if (!out) throw std::runtime_error("write failed (disk full?)");
    out.close();  // the last buffered bytes: a full disk often shows only here
    if (!out) throw std::runtime_error("write failed (disk full?)");
  });
}

void write_text_atomically(const std::string& path, const std::string& text) {
  write_stream_atomically(path, [&](std::ostream& out) { out << text; });
}

void write_image_atomically(const std::string& path, const cv::Mat& image) {
  if (image.empty()) throw std::runtime_error("cannot write " + path + ": empty image");
  // Encoded in memory: cv::imwrite ignores a failed final flush and would report a truncated
  // file as written.
  std::vector<uchar> bytes;
  try {
    if (!cv::imencode(fs::path(path).extension().string(), image, bytes))
      throw std::runtime_error("cannot write " + path + ": cannot encode the image");
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot write " + path + ": cannot encode the image (" +
                             std::string(e.err) + ")");
  }
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  });
}

FileGroup::FileGroup() {
  if (current_group) {
    outer_ = current_group;
    done_ = true;
  } else {
    current_group = this;
  }
}

FileGroup::~FileGroup() {
  if (current_group == this) current_group = nullptr;
  if (done_) return;
  for (const auto& f : files_) remove_quietly(f.first);
  for (auto it = folders_.rbegin(); it != folders_.rend(); ++it) {
    std::error_code ec;
    if (fs::is_empty(*it, ec) && !ec) fs::remove(*it, ec);
  }
}

void FileGroup::create_folders(const std::string& dir) {
  if (outer_) return outer_->create_folders(dir);
  if (dir.empty()) throw std::runtime_error("output folder: empty path");
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::runtime_error("output folder " + dir + ": exists and is not a folder");
  std::vector<fs::path> missing;  // outermost last
  for (fs::path p = fs::absolute(dir, ec).lexically_normal(); !p.empty() && !fs::exists(p, ec);
       p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  for (auto it = missing.rbegin(); it != missing.rend(); ++it)
    if (fs::is_directory(*it)) folders_.push_back(it->string());
  if (ec)
    throw std::runtime_error("output folder " + dir + ": cannot create (" + ec.message() + ")");
}

void FileGroup::commit() {
  if (outer_) return;
  if (current_group == this) current_group = nullptr;  // later writes are on their own
  done_ = true;
  for (size_t i = 0; i < files_.size(); ++i) {
    std::error_code ec;
    fs::rename(files_[i].first, files_[i].second, ec);
    if (ec) {
      for (size_t k = i; k < files_.size(); ++k) remove_quietly(files_[k].first);
      const std::string target = files_[i].second;
      files_.clear();
      throw std::runtime_error("cannot write " + target + ": " + ec.message());
    }
  }
  files_.clear();
}

}  // namespace orthoface::io
