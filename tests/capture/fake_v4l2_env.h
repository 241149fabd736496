#pragma once
// Runs a test body in a child process that has the fake V4L2 device preloaded (LD_PRELOAD must
// be set before a process starts). Pattern:
//   TEST(V4l2Camera, X) { RUN_IN_FAKE_V4L2_CHILD(); ...body, runs in the child... }
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace orthoface::testing {

inline constexpr const char* kFakeDevices = "/dev/video42,/dev/video43";

inline bool under_fake_v4l2() { return std::getenv("ORTHOFACE_FAKE_V4L2") != nullptr; }

// Control folder of the fake (unplug / EIO switches), fresh per test.
inline std::string fake_ctl_dir() {
  const char* d = std::getenv("ORTHOFACE_FAKE_V4L2_CTL");
  return d ? d : "";
}

// Re-runs the current test in a child with the fake preloaded; returns its exit status.
inline int rerun_under_fake_v4l2(const std::string& devices = kFakeDevices) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string filter =
      std::string("--gtest_filter=") + info->test_suite_name() + "." + info->name();
  const auto ctl = std::filesystem::temp_directory_path() /
                   ("orthoface_fake_ctl_" + std::to_string(getpid()) + "_" + info->name());
  std::filesystem::remove_all(ctl);
  std::filesystem::create_directories(ctl);
  const pid_t pid = fork();
  if (pid == 0) {
    setenv("LD_PRELOAD", FAKE_V4L2_LIB, 1);
    setenv("ORTHOFACE_FAKE_V4L2", devices.c_str(), 1);
    setenv("ORTHOFACE_FAKE_V4L2_CTL", ctl.c_str(), 1);
    execl("/proc/self/exe", "capture_test", filter.c_str(), "--gtest_brief=1",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  std::filesystem::remove_all(ctl);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace orthoface::testing

// In the parent: runs this test again in a child under the fake, checks it passed, returns.
#define RUN_IN_FAKE_V4L2_CHILD()                                                               \
  if (!orthoface::testing::under_fake_v4l2()) {                                                \
    EXPECT_EQ(orthoface::testing::rerun_under_fake_v4l2(), 0) << "test under the fake failed"; \
    return;                                                                                    \
  }
