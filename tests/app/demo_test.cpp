// `orthoface demo`, run as a separate process.
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "tests/common/run_command.h"
#include "tests/common/test_data.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;

using testing::slurp;

// Exit code of `orthoface <args>` run in `work`; stdout / stderr land in work/out.txt, err.txt.
int run_demo(const std::string& args, const fs::path& work) {
  return testing::run_orthoface(args, work).code;
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
  // The synthesized 45-degree views of the simulated subjects against their true views (the
  // face mask reaches forehead_top and below the chin: the model must cover all of it).
  for (const char* seed : {"seed 0 ", "seed 1 ", "seed 2 "}) {
    const size_t line = out.find(std::string("  ") + seed);
    ASSERT_NE(line, std::string::npos) << out;
    double psnr = 0, ssim = 0;
    const size_t at = out.find("yaw 45: PSNR", line);
    ASSERT_EQ(std::sscanf(out.c_str() + at, "yaw 45: PSNR %lf dB, SSIM %lf", &psnr, &ssim), 2)
        << out;
    EXPECT_GT(psnr, 27.0) << seed;
    EXPECT_GT(ssim, 0.91) << seed;
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
