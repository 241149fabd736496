// The command-line table parser (app/cli.h) on its own.
#include "app/cli.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace orthoface::app {
namespace {

const Command kCommand{"try",
                       "a command for the test",
                       "orthoface try DIR [options]",
                       {{"o", true, "FILE  output"},
                        {"yaw", true, "DEG  yaw"},
                        {"k", true, "K  neighbours"},
                        {"fast", false, "a switch"}},
                       1};

Args parse(std::vector<std::string> words) {
  words.insert(words.begin(), {"orthoface", "try"});
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  return parse_args(kCommand, static_cast<int>(argv.size()), argv.data());
}

std::string error_of(const std::vector<std::string>& words) {
  try {
    parse(words);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Cli, ParsesValuesSwitchesAndPositionals) {
  const Args a = parse({"dir", "--yaw", "-30", "-o", "v.png", "--fast", "--k=5"});
  EXPECT_FALSE(a.help);
  ASSERT_EQ(a.positional, std::vector<std::string>{"dir"});
  EXPECT_EQ(a.get("yaw"), "-30");  // a negative number is a value, not a flag
  EXPECT_EQ(a.get("o"), "v.png");
  EXPECT_EQ(a.get("k"), "5");
  EXPECT_TRUE(a.has("fast"));
  EXPECT_FALSE(parse({"dir"}).has("fast"));
  EXPECT_EQ(parse({"--k", "3"}).get("k"), "3");  // one-letter flags in both spellings
  EXPECT_EQ(parse({"--o", "x"}).get("o"), "x");
  EXPECT_EQ(parse({}).get("yaw", "0"), "0");
}

TEST(Cli, HelpWinsOverEverythingElse) {
  EXPECT_TRUE(parse({"--help"}).help);
  EXPECT_TRUE(parse({"-h", "--bogus", "a", "b"}).help);
}

TEST(Cli, BadCommandLinesNameTheCommandAndTheFlag) {
  const std::pair<std::vector<std::string>, std::string> cases[] = {
      {{"--bogus"}, "--bogus"},
      {{"-x", "3"}, "-x"},
      {{"--yaw"}, "--yaw needs a value"},
      {{"--yaw", "1", "--yaw", "2"}, "--yaw given twice"},
      {{"--fast", "--fast"}, "--fast given twice"},
      {{"a", "b"}, "unexpected argument 'b'"},
  };
  for (const auto& [words, needle] : cases) {
    const std::string e = error_of(words);
    EXPECT_EQ(e.rfind("try: ", 0), 0u) << e;
    EXPECT_NE(e.find(needle), std::string::npos) << needle << " in: " << e;
    EXPECT_NE(e.find("orthoface try --help"), std::string::npos) << e;
  }
}

// Error messages reach the terminal as one printable line whatever a file put in them.
TEST(Cli, OneLineEscapesWhatAFileCouldInject) {
  EXPECT_EQ(one_line("plain message"), "plain message");
  EXPECT_EQ(one_line("OpenCV: assertion\n in function 'f'\n"),
            "OpenCV: assertion; in function 'f'");
  EXPECT_EQ(one_line("a\r\n\nb"), "a; b");
  EXPECT_EQ(one_line("bad byte \x1b[2J here\tand\xff"), "bad byte \\x1b[2J here and\\xff");
  EXPECT_EQ(one_line(""), "");
  EXPECT_EQ(one_line("\n\n"), "");
}

TEST(Cli, TypedGettersCheckRanges) {
  EXPECT_EQ(to_int("k", "7", 1, 10), 7);
  EXPECT_THROW(to_int("k", "0", 1, 10), std::invalid_argument);
  EXPECT_THROW(to_int("k", "7x", 1, 10), std::invalid_argument);
  EXPECT_DOUBLE_EQ(to_double("yaw", "-30.5", -90, 90), -30.5);
  EXPECT_THROW(to_double("yaw", "nan", -90, 90), std::invalid_argument);
  EXPECT_EQ(to_size("size", "640x480", 4096), (std::pair<int, int>{640, 480}));
  EXPECT_THROW(to_size("size", "640", 4096), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::app
