// Files written all or nothing: the content goes to a temporary file beside the target, which
// is renamed onto it only when complete, so a failure (full disk, bad encoder, an exception
// half-way) never leaves a partial file and never touches an existing one.
#pragma once

#include <functional>
#include <ostream>
#include <string>

#include <opencv2/core.hpp>

namespace orthoface::io {

// A temporary path beside `path`: the same folder, a hidden name no user file is likely to have
// (".NAME.orthoface-PID-N.tmpEXT", unique within the process), and `path`'s extension, so
// encoders that choose the format by extension (cv::imwrite, cv::FileStorage) work on it.
std::string temp_path_for(const std::string& path);

// `write(tmp)` writes the whole file at `tmp` (temp_path_for(path)); it is then renamed onto
// `path`. When `write` throws, or the rename fails, the temporary is removed and
// std::runtime_error is thrown: "cannot write PATH: REASON" (`write`'s own message as reason).
// A `path` that exists as anything but a regular file (a device node, a folder, a symbolic link)
// is refused before anything is written.
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp)>& write);

// The same with `write` filling a binary output stream; a stream in a failed state after it
// (e.g. a full disk) is a failure.
void write_stream_atomically(const std::string& path,
                             const std::function<void(std::ostream& out)>& write);

// Bytes or text as they are.
void write_text_atomically(const std::string& path, const std::string& text);

// `image` encoded by `path`'s extension (cv::imwrite; .png, .jpg, .bmp, ...). Throws
// std::runtime_error naming `path` when the image is empty or cannot be encoded or written.
void write_image_atomically(const std::string& path, const cv::Mat& image);

}  // namespace orthoface::io
