// Files written all or nothing: the content goes to a temporary file beside the target, which
// is renamed onto it only when complete, so a failure (full disk, bad encoder, an exception
// half-way) never leaves a partial file and never touches an existing one.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::io {

// A temporary path beside `path`: the same folder, a hidden name no user file is likely to have
// (".NAME.orthoface-PID-N.tmpEXT", unique within the process), and `path`'s extension, so
// encoders that choose the format by extension (cv::imwrite, cv::FileStorage) work on it.
std::string temp_path_for(const std::string& path);

// `write(tmp)` writes the whole file at `tmp` (temp_path_for(path)); it is then renamed onto
// `path` (or, while a FileGroup is open on this thread, when that group commits). When `write`
// throws (anything), or the rename fails, the temporary is removed and std::runtime_error is
// thrown: "cannot write PATH: REASON" (`write`'s own message as reason).
// A `path` that exists as anything but a regular file (a device node, a folder, a symbolic link)
// is refused before anything is written.
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& tmp)>& write);

// The same with `write` filling a binary output stream; a stream in a failed state after it,
// or a close that fails (a full disk, a file size limit), is a failure.
void write_stream_atomically(const std::string& path,
                             const std::function<void(std::ostream& out)>& write);

// Bytes or text as they are.
void write_text_atomically(const std::string& path, const std::string& text);

// `image` encoded by `path`'s extension (cv::imencode; .png, .jpg, .bmp, ...) in memory, then
// written as bytes, so a write that fails anywhere (even in the last flush) is seen. Throws
// std::runtime_error naming `path` when the image is empty or cannot be encoded or written.
void write_image_atomically(const std::string& path, const cv::Mat& image);

// Several files that appear together or not at all (an OBJ with its MTL and texture, a
// command's outputs). While a group is open, every write_*atomically call on this thread
// leaves its complete temporary in place; commit() renames them all onto their targets. A group
// destroyed without commit() (an exception on the way) removes every temporary and every folder
// it created that is still empty, so a failure leaves nothing behind. A group opened while
// another is open on the same thread joins it: only the outermost one commits or cleans up.
// One thread's files only; not copyable.
class FileGroup {
 public:
  FileGroup();
  ~FileGroup();
  FileGroup(const FileGroup&) = delete;
  FileGroup& operator=(const FileGroup&) = delete;

  // Creates `dir` and its missing parents; those created are removed again (when still empty)
  // if the group is not committed. Throws std::runtime_error naming `dir` when it cannot be
  // created or exists as something other than a folder.
  void create_folders(const std::string& dir);

  // Renames every file written in the group onto its target, in the order written. Throws
  // std::runtime_error "cannot write PATH: REASON" when a rename fails; the files not renamed
  // yet are then removed (those already renamed stay: they are complete).
  void commit();

 private:
  friend void write_atomically(const std::string&, const std::function<void(const std::string&)>&);
  FileGroup* outer_ = nullptr;                              // the group this one joined
  std::vector<std::pair<std::string, std::string>> files_;  // (temporary, target)
  std::vector<std::string> folders_;                        // created here, deepest last
  bool done_ = false;                                       // committed or joined
};

}  // namespace orthoface::io
