#pragma once

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

namespace orthoface::testing {

// Path of a file under ../shared/data, or "" when the data folder is absent (tests then call
// GTEST_SKIP so the suite passes without it).
inline std::string shared_data(const std::string& relative) {
  const std::filesystem::path p = std::filesystem::path(ORTHOFACE_DATA_DIR) / relative;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

// A fresh empty folder under the test temp dir, named after the test and this process (ctest
// runs each test in its own process, several at once, so a shared name would race).
inline std::filesystem::path temp_dir(const std::string& name) {
  const auto p = std::filesystem::temp_directory_path() /
                 ("orthoface_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

// Moves the fixture made in `work` to `ready`, where test processes running at once share it.
// A copy in place is never deleted under a process reading it: a fresh one (`fresh()`: another
// process won the race) is kept and `work` dropped; a stale one (made by an older binary) is
// moved aside whole first. Returns `ready`.
inline std::filesystem::path publish_fixture(const std::filesystem::path& work,
                                             const std::filesystem::path& ready,
                                             const std::function<bool()>& fresh) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fresh() && fs::exists(ready)) {
    const fs::path stale = work.string() + ".stale";
    fs::rename(ready, stale, ec);
    fs::remove_all(stale, ec);
  }
  fs::rename(work, ready, ec);
  if (ec) fs::remove_all(work, ec);
  return ready;
}

}  // namespace orthoface::testing
