#include "io/atomic_file.h"

#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/common/test_data.h"

namespace orthoface::io {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

// Nothing but `expected` is left in `dir` (no temporary).
void expect_only(const fs::path& dir, const std::set<std::string>& expected) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  EXPECT_EQ(names, expected);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(AtomicFile, TempPathIsBesideHiddenUniqueAndKeepsTheExtension) {
  const std::string a = temp_path_for("/some/dir/view.png");
  const std::string b = temp_path_for("/some/dir/view.png");
  EXPECT_NE(a, b);
  EXPECT_EQ(fs::path(a).parent_path(), "/some/dir");
  EXPECT_EQ(fs::path(a).extension(), ".png");
  EXPECT_EQ(fs::path(a).filename().string()[0], '.');
  EXPECT_NE(a, "/some/dir/view.png.tmp");  // a user's own file of that name is never touched
  EXPECT_EQ(fs::path(temp_path_for("rel.txt")).parent_path(), "");
}

TEST(AtomicFile, WritesTextImagesAndStreams) {
  const fs::path dir = testing::temp_dir("atomic_write");
  write_text_atomically((dir / "a.json").string(), "{\"x\": 1}\n");
  EXPECT_EQ(slurp(dir / "a.json"), "{\"x\": 1}\n");
  write_text_atomically((dir / "a.json").string(), "replaced");
  EXPECT_EQ(slurp(dir / "a.json"), "replaced");
  const cv::Mat image(8, 12, CV_8UC3, cv::Scalar(10, 20, 30));
  write_image_atomically((dir / "i.png").string(), image);
  const cv::Mat back = cv::imread((dir / "i.png").string());
  EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0);
  write_stream_atomically((dir / "b.bin").string(),
                          [](std::ostream& out) { out.write("\0\1", 2); });
  EXPECT_EQ(slurp(dir / "b.bin"), std::string("\0\1", 2));
  expect_only(dir, {"a.json", "i.png", "b.bin"});
  fs::remove_all(dir);
}

// A failure leaves the old file as it was and no temporary behind; the error names the path.
TEST(AtomicFile, FailuresLeaveTheOldFileAndNoTemporary) {
  const fs::path dir = testing::temp_dir("atomic_fail");
  const std::string path = (dir / "out.txt").string();
  write_text_atomically(path, "old");
  std::string e = error_of([&] {
    write_stream_atomically(path, [](std::ostream& out) {
      out << "half";
      throw std::runtime_error("encoder gave up");
    });
  });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find("encoder gave up"), std::string::npos) << e;
  e = error_of([&] {
    write_stream_atomically(path, [](std::ostream& out) {
      out << "half";
      out.setstate(std::ios::badbit);  // as a full disk would
    });
  });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_EQ(slurp(path), "old");
  expect_only(dir, {"out.txt"});

  fs::create_directories(dir / "folder");  // a folder where the file should go: rename fails
  e = error_of([&] { write_text_atomically((dir / "folder").string(), "x"); });
  EXPECT_NE(e.find("folder"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_directory(dir / "folder"));
  expect_only(dir, {"out.txt", "folder"});
  fs::remove_all(dir);
}

// A device node, a folder or a link at the target is never replaced by the rename.
TEST(AtomicFile, NonRegularTargetsAreRefusedAndLeftAsTheyAre) {
  const fs::path dir = testing::temp_dir("atomic_special");
  fs::create_directories(dir / "folder.png");
  fs::create_symlink(dir / "elsewhere.txt", dir / "link.txt");
  ASSERT_EQ(::mkfifo((dir / "fifo.txt").c_str(), 0600), 0);  // a special file, as a device is
  for (const fs::path& target : {dir / "folder.png", dir / "link.txt", dir / "fifo.txt"}) {
    try {
      write_text_atomically(target.string(), "x");
      ADD_FAILURE() << target;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_directory(dir / "folder.png"));
  EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
  EXPECT_FALSE(fs::exists(dir / "elsewhere.txt"));
  EXPECT_TRUE(fs::is_fifo(dir / "fifo.txt"));
  EXPECT_THROW(write_image_atomically((dir / "folder.png").string(), cv::Mat(4, 4, CV_8UC3)),
               std::runtime_error);
}

TEST(AtomicFile, BadImagesAndMissingFoldersThrow) {
  const fs::path dir = testing::temp_dir("atomic_bad");
  const cv::Mat image(4, 4, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(write_image_atomically((dir / "e.png").string(), cv::Mat()), std::runtime_error);
  EXPECT_THROW(write_image_atomically((dir / "e.unknown").string(), image), std::runtime_error);
  EXPECT_THROW(write_image_atomically((dir / "no" / "e.png").string(), image), std::runtime_error);
  EXPECT_THROW(write_text_atomically((dir / "no" / "t.txt").string(), "x"), std::runtime_error);
  expect_only(dir, {});
  fs::remove_all(dir);
}

// A full disk as a file size limit (RLIMIT_FSIZE, SIGXFSZ ignored: write() fails with EFBIG) in
// a child process: `f` runs there, and its return value is the child's exit status.
int with_file_size_limit(long bytes, const std::function<int()>& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const rlimit limit{rlim_t(bytes), rlim_t(bytes)};
    ::signal(SIGXFSZ, SIG_IGN);
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(100);
    ::_exit(f());
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// 0 when `f` throws std::runtime_error naming `path`, 1 when it does not throw, 2 when the
// message does not name it.
int throws_naming(const std::string& path, const std::function<void()>& f) {
  const std::string e = error_of(f);
  return e.empty() ? 1 : e.find(path) == std::string::npos ? 2 : 0;
}

// A write that fails only in the last flush (the content fits the stream's buffer, not the
// disk) and an image whose encoded bytes do not fit are failures: the old file stays as it was
// and no temporary is left.
TEST(AtomicFile, AFullDiskIsAFailureEvenAtTheLastFlush) {
  const fs::path dir = testing::temp_dir("atomic_full");
  const std::string text = (dir / "a.txt").string(), png = (dir / "i.png").string();
  write_text_atomically(text, "old");
  cv::Mat noise(64, 64, CV_8UC3);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(255));  // ~12 kB of PNG
  EXPECT_EQ(with_file_size_limit(4096,
                                 [&] {
                                   return throws_naming(text, [&] {
                                     write_text_atomically(text, std::string(5000, 'x'));
                                   });
                                 }),
            0);
  EXPECT_EQ(
      with_file_size_limit(
          4096, [&] { return throws_naming(png, [&] { write_image_atomically(png, noise); }); }),
      0);
  EXPECT_EQ(slurp(text), "old");
  expect_only(dir, {"a.txt"});
  // With room, the same image is written whole.
  EXPECT_EQ(
      with_file_size_limit(
          1 << 20, [&] { return throws_naming(png, [&] { write_image_atomically(png, noise); }); }),
      1);
  EXPECT_EQ(cv::norm(cv::imread(png), noise, cv::NORM_INF), 0);
  fs::remove_all(dir);
}

TEST(FileGroup, FilesAppearTogetherAtCommit) {
  const fs::path dir = testing::temp_dir("group_commit");
  {
    FileGroup group;
    group.create_folders((dir / "out" / "sub").string());
    write_text_atomically((dir / "out" / "sub" / "a.txt").string(), "a");
    write_text_atomically((dir / "out" / "b.txt").string(), "b");
    EXPECT_FALSE(fs::exists(dir / "out" / "b.txt"));  // not before the commit
    EXPECT_FALSE(fs::exists(dir / "out" / "sub" / "a.txt"));
    group.commit();
    EXPECT_TRUE(fs::exists(dir / "out" / "b.txt"));
    write_text_atomically((dir / "out" / "c.txt").string(), "c");  // after it: on its own
    EXPECT_TRUE(fs::exists(dir / "out" / "c.txt"));
  }
  EXPECT_EQ(slurp(dir / "out" / "sub" / "a.txt"), "a");
  EXPECT_EQ(slurp(dir / "out" / "b.txt"), "b");
  expect_only(dir / "out", {"sub", "b.txt", "c.txt"});
  fs::remove_all(dir);
}

// A group that is not committed (an exception on the way) leaves nothing: no temporary, no
// target, no folder it created; an existing file keeps its content; a folder that existed stays.
TEST(FileGroup, AFailureLeavesNothingBehind) {
  const fs::path dir = testing::temp_dir("group_fail");
  write_text_atomically((dir / "keep.txt").string(), "old");
  try {
    FileGroup group;
    group.create_folders((dir / "new" / "deeper").string());
    write_text_atomically((dir / "keep.txt").string(), "new");
    write_text_atomically((dir / "new" / "deeper" / "x.txt").string(), "x");
    {
      FileGroup inner;  // joins: its commit is the outer one's
      write_text_atomically((dir / "inner.txt").string(), "i");
      inner.commit();
      EXPECT_FALSE(fs::exists(dir / "inner.txt"));  // the outer group holds it
    }
    write_stream_atomically((dir / "bad.txt").string(), [](std::ostream& out) {
      out << "half";
      out.setstate(std::ios::badbit);  // as a full disk would
    });
    group.commit();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(dir / "keep.txt"), "old");
  expect_only(dir, {"keep.txt"});
  fs::remove_all(dir);
}

TEST(FileGroup, BadFoldersAndRenamesThrowNamingThePath) {
  const fs::path dir = testing::temp_dir("group_bad");
  write_text_atomically((dir / "file").string(), "f");
  FileGroup group;
  EXPECT_THROW(group.create_folders(""), std::runtime_error);
  std::string e = error_of([&] { group.create_folders((dir / "file").string()); });
  EXPECT_NE(e.find("file"), std::string::npos) << e;
  e = error_of([&] { group.create_folders((dir / "file" / "below").string()); });
  EXPECT_NE(e.find("below"), std::string::npos) << e;
  // A folder that appears at a target between the write and the commit: the rename fails, the
  // error names it and the temporaries go.
  write_text_atomically((dir / "a.txt").string(), "a");
  write_text_atomically((dir / "b.txt").string(), "b");
  fs::create_directories(dir / "a.txt" / "x");
  e = error_of([&] { group.commit(); });
  EXPECT_NE(e.find("a.txt"), std::string::npos) << e;
  expect_only(dir, {"file", "a.txt"});
  EXPECT_TRUE(fs::is_directory(dir / "a.txt"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace orthoface::io
