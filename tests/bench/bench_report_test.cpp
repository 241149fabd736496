// The report every benchmark ends with: its folder made before the run, both files written whole.
#include "bench/bench_report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tests/common/test_data.h"

namespace {

namespace fs = std::filesystem;
namespace ob = orthoface::bench;

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST(BenchReport, MeanAndMedianOfNothingAreNaN) {
  EXPECT_DOUBLE_EQ(ob::mean({1, 2, 6}), 3.0);
  EXPECT_DOUBLE_EQ(ob::median({5, 1, 3}), 3.0);
  EXPECT_DOUBLE_EQ(ob::median({4, 1, 3, 2}), 3.0);  // the upper middle value
  EXPECT_TRUE(std::isnan(ob::mean({})));
  EXPECT_TRUE(std::isnan(ob::median({})));
}

// live_bench used to write its frames into a folder nobody made (they were lost without a word)
// and then fail on the report after the whole run.
TEST(BenchReport, TheOutputFolderIsMadeAndTheReportWrittenWhole) {
  const fs::path dir = orthoface::testing::temp_dir("bench_report") / "a" / "b";
  fs::remove_all(dir.parent_path());
  ob::make_out_dir(dir.string());
  EXPECT_TRUE(fs::is_directory(dir));
  ob::make_out_dir("");  // no folder asked for: nothing to do
  const fs::path later = dir.parent_path() / "made_by_the_report";
  ob::write_report(later.string(), "r", {{"x", 1}}, "| x |\n");
  EXPECT_EQ(read(later / "r.md"), "| x |\n");
  EXPECT_EQ(nlohmann::json::parse(read(later / "r.json"))["x"], 1);
  for (const auto& e : fs::directory_iterator(later))
    EXPECT_NE(e.path().extension(), ".part") << e.path();
}

TEST(BenchReport, AFolderThatCannotBeMadeIsNamed) {
  const fs::path dir = orthoface::testing::temp_dir("bench_report_bad");
  const fs::path file = dir / "a_file";
  std::ofstream(file) << "x";
  try {
    ob::make_out_dir((file / "out").string());
    FAIL() << "a folder inside a file was made";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((file / "out").string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(ob::write_report(file.string(), "r", {}, ""), std::runtime_error);
  EXPECT_EQ(read(file), "x");  // the file in the way is left as it was
}
