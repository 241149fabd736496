#pragma once

#include <map>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "vision/observe.h"

namespace orthoface::app {

// One flag of a command: "--name VALUE" when takes_value, else "--name".
struct Flag {
  std::string name;  // without the leading dashes
  bool takes_value = true;
  std::string help;  // one line for --help; a value placeholder may lead: "DIR  output folder"
};

struct Command {
  std::string name;     // "simulate"
  std::string summary;  // one line for `orthoface --help`
  std::string usage;    // "orthoface simulate --subject N --out DIR [options]"
  std::vector<Flag> flags;
  int max_positional = 0;  // how many bare arguments it takes
};

// Parsed command line. Values are strings; the typed getters below check and convert them.
struct Args {
  std::map<std::string, std::string> values;  // flag -> value ("" for switches)
  std::vector<std::string> positional;
  bool help = false;
  bool has(const std::string& flag) const { return values.count(flag) > 0; }
  std::string get(const std::string& flag, const std::string& fallback = "") const;
};

// Parses argv[2..] (argv[1] is the command name). Throws std::invalid_argument naming the
// unknown flag, the missing value or the extra argument.
Args parse_args(const Command& command, int argc, char** argv);

// Prints usage and flag help to stdout.
void print_help(const Command& command);

// Typed conversions; each throws std::invalid_argument naming the flag and the bad text.
int to_int(const std::string& flag, const std::string& text, int min, int max);
double to_double(const std::string& flag, const std::string& text, double min, double max);
// "640x480" -> {640, 480}; each side in [1, max_side].
std::pair<int, int> to_size(const std::string& flag, const std::string& text, int max_side);

// Makes `dir` usable as an output folder (creates it and its parents). Throws
// std::runtime_error if it exists as a file or cannot be created or written. With `group`, the
// folders created are removed again when the group's files are not committed (a failed run
// leaves no empty output folder behind).
void prepare_output_dir(const std::string& dir, io::FileGroup* group = nullptr);

// Throws std::runtime_error when `path` is missing or not a regular file; `what` names it.
void require_file(const std::string& path, const std::string& what);

// One clean plate (a camera's empty scene) from `path`, read as every photo is
// (vision::read_image); with width > 0 it must be width x height. Throws std::runtime_error
// naming `what` (the flag) and the file when it is missing, unreadable or of another size.
cv::Mat read_clean_plate(const std::string& path, const std::string& what, int width = 0,
                         int height = 0);

// The clean plates (each camera's empty scene) of --front-background / --side-background, when
// given, into `options`; with width > 0 each must be width x height (the capture size). Throws
// std::runtime_error naming the flag and file when one is missing, unreadable or of another size.
void read_clean_plates(const Args& a, vision::ObserveOptions& options, int width = 0,
                       int height = 0);

// `message` as one printable line: line breaks become "; ", other control and non-ASCII bytes
// \xNN (a file's bytes echoed in an error cannot move the cursor or end the line), trailing
// blanks dropped. main() prints every error through it.
std::string one_line(const std::string& message);

// The help lines of those two flags.
Flag front_background_flag();
Flag side_background_flag();

}  // namespace orthoface::app
