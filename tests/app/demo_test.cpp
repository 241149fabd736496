// `orthoface demo`, run as a separate process.
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Exit code of `orthoface <args>` run in `work`; stdout / stderr land in work/out.txt, err.txt.
int run_demo(const std::string& args, const fs::path& work) {
  const std::string cmd = "cd '" + work.string() + "' && '" + ORTHOFACE_BINARY + "' " + args +
                          " >out.txt 2>err.txt";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(DemoCommand, WritesAContactSheetAndOneFolderPerSubject) {
  const fs::path work = testing::temp_dir("app_demo");
  ASSERT_EQ(run_demo("demo --out d", work), 0) << slurp(work / "err.txt");
  const std::string out = slurp(work / "out.txt");
  EXPECT_EQ(out.rfind("demo: ", 0), 0u) << out;
  EXPECT_NE(out.find("contact_sheet.png"), std::string::npos);
  const cv::Mat sheet = cv::imread((work / "d" / "contact_sheet.png").string());
  ASSERT_FALSE(sheet.empty());
  EXPECT_GT(sheet.cols, 1000);  // five 320-px columns
  const int rows = testing::shared_data("lee_perry_smith_head").empty() ? 3 : 4;
  EXPECT_GT(sheet.rows, rows * 240);
  for (const char* sub : {"subject_0", "subject_1", "subject_2"}) {
    EXPECT_TRUE(fs::exists(work / "d" / sub / "sim" / "front.png")) << sub;
    EXPECT_TRUE(fs::exists(work / "d" / sub / "sim" / "landmarks.json")) << sub;
  }
}

TEST(DemoCommand, BadInputGivesOneErrorLine) {
  const fs::path work = testing::temp_dir("app_demo_bad");
  std::ofstream(work / "a_file") << "keep";
  for (const std::string args : {"demo --out a_file", "demo --bogus", "demo extra"}) {
    EXPECT_NE(run_demo(args, work), 0) << args;
    const std::string err = slurp(work / "err.txt");
    EXPECT_EQ(err.rfind("error: ", 0), 0u) << args << ": " << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << args << ": " << err;
  }
  EXPECT_EQ(slurp(work / "a_file"), "keep");
  EXPECT_FALSE(fs::exists(work / "orthoface-demo"));
}

}  // namespace
}  // namespace orthoface::app
