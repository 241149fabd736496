#include "app/cli.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include "vision/image_prep.h"

namespace orthoface::app {

std::string Args::get(const std::string& flag, const std::string& fallback) const {
  auto it = values.find(flag);
  return it == values.end() ? fallback : it->second;
}

Args parse_args(const Command& command, int argc, char** argv) {
  // CLI11 parses; the command's table says what it accepts. Values stay strings here: the typed
  // getters below check and convert them with the flag's name in the message.
  CLI::App app(command.summary, "orthoface " + command.name);
  app.set_help_flag();  // --help / -h are handled below, to print our own layout
  bool help = false;
  app.add_flag("-h,--help", help);
  std::map<std::string, std::string> values;
  std::map<std::string, bool> switches;
  std::vector<std::pair<std::string, CLI::Option*>> options;
  for (const Flag& f : command.flags) {
    // One-letter flags answer to both -k and --k, as the help writes them.
    const std::string name = (f.name.size() == 1 ? "-" + f.name + "," : "") + "--" + f.name;
    CLI::Option* o =
        f.takes_value ? app.add_option(name, values[f.name]) : app.add_flag(name, switches[f.name]);
    o->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    options.emplace_back(f.name, o);
  }
  std::vector<std::string> positional;
  app.add_option("args", positional);  // counted below, to name the extra one
  auto fail = [&](const std::string& why) {
    return std::invalid_argument(command.name + ": " + why + " (see orthoface " + command.name +
                                 " --help)");
  };
  try {
    app.parse(argc - 1, argv + 1);  // argv[1], the command's name, stands in for the program
  } catch (const CLI::ParseError& e) {
    if (help) return Args{{}, {}, true};
    std::string why = e.what();  // CLI11's wording, with its "N required TEXT missing" made plain
    if (const auto at = why.find(": 1 required TEXT missing"); at != std::string::npos)
      why = "flag " + why.substr(0, at) + " needs a value";
    throw fail(why);
  }
  Args args;
  args.help = help;
  if (help) return args;
  for (const auto& [name, o] : options) {
    if (o->count() > 1) throw fail("flag " + o->get_name() + " given twice");
    if (o->count() > 0) args.values[name] = values.count(name) ? values[name] : std::string();
  }
  if (static_cast<int>(positional.size()) > command.max_positional)
    throw fail("unexpected argument '" + positional[command.max_positional] + "'");
  args.positional = positional;
  return args;
}

void print_help(const Command& command) {
  std::cout << "usage: " << command.usage << "\n\n" << command.summary << "\n";
  if (!command.flags.empty()) std::cout << "\noptions:\n";
  for (const Flag& f : command.flags) {
    std::string lhs = (f.name.size() == 1 ? "-" : "--") + f.name;
    std::string help = f.help;
    if (f.takes_value) {
      // A leading upper-case word in the help is the value placeholder.
      auto sp = help.find("  ");
      if (sp != std::string::npos) {
        lhs += " " + help.substr(0, sp);
        help = help.substr(sp + 2);
      } else {
        lhs += " VALUE";
      }
    }
    std::cout << "  " << lhs;
    for (size_t k = lhs.size(); k < 26; ++k) std::cout << ' ';
    std::cout << " " << help << "\n";
  }
  std::cout << "  --help                     show this help\n";
}

int to_int(const std::string& flag, const std::string& text, int min, int max) {
  errno = 0;
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE)
    throw std::invalid_argument("--" + flag + ": expected an integer, got '" + text + "'");
  if (v < min || v > max)
    throw std::invalid_argument("--" + flag + ": " + text + " is outside [" + std::to_string(min) +
                                ", " + std::to_string(max) + "]");
  return static_cast<int>(v);
}

double to_double(const std::string& flag, const std::string& text, double min, double max) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw std::invalid_argument("--" + flag + ": expected a number, got '" + text + "'");
  if (v < min || v > max) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "--%s: %s is outside [%g, %g]", flag.c_str(), text.c_str(), min,
                  max);
    throw std::invalid_argument(buf);
  }
  return v;
}

std::pair<int, int> to_size(const std::string& flag, const std::string& text, int max_side) {
  const auto x = text.find('x');
  if (x == std::string::npos)
    throw std::invalid_argument("--" + flag + ": expected WxH such as 640x480, got '" + text + "'");
  const std::string w = text.substr(0, x), h = text.substr(x + 1);
  try {
    return {to_int(flag, w, 1, max_side), to_int(flag, h, 1, max_side)};
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("--" + flag + ": size '" + text +
                                "' must be WxH with each side in 1.." + std::to_string(max_side));
  }
}

void prepare_output_dir(const std::string& dir, io::FileGroup* group) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw std::runtime_error("output folder: empty path");
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::runtime_error("output folder " + dir + ": exists and is not a folder");
  if (group) {
    group->create_folders(dir);
  } else {
    fs::create_directories(dir, ec);
    if (ec)
      throw std::runtime_error("output folder " + dir + ": cannot create (" + ec.message() + ")");
  }
  const fs::path probe = fs::path(dir) / ".orthoface-write-probe";
  {
    std::ofstream f(probe);
    if (!f) throw std::runtime_error("output folder " + dir + ": not writable");
  }
  fs::remove(probe, ec);
}

void require_file(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (path.empty()) throw std::runtime_error(what + ": no path given");
  if (!std::filesystem::exists(path, ec))
    throw std::runtime_error(what + " " + path + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error(what + " " + path + ": not a regular file");
}

cv::Mat read_clean_plate(const std::string& path, const std::string& what, int width, int height) {
  require_file(path, what);
  cv::Mat plate;
  try {
    plate = vision::read_image(path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(what + ": " + e.what());
  }
  if (width > 0 && (plate.cols != width || plate.rows != height))
    throw std::runtime_error(what + " " + path + ": " + std::to_string(plate.cols) + "x" +
                             std::to_string(plate.rows) + ", the cameras capture " +
                             std::to_string(width) + "x" + std::to_string(height));
  return plate;
}

void read_clean_plates(const Args& a, vision::ObserveOptions& options, int width, int height) {
  for (const char* flag : {"front-background", "side-background"})
    if (a.has(flag))
      (flag[0] == 'f' ? options.background_front : options.background_side) =
          read_clean_plate(a.get(flag), std::string("--") + flag, width, height);
}

std::string one_line(const std::string& message) {
  std::string out;
  for (size_t i = 0; i < message.size(); ++i) {
    const unsigned char c = message[i];
    if (c == '\n' || c == '\r') {
      while (i + 1 < message.size() && (message[i + 1] == '\n' || message[i + 1] == '\r')) ++i;
      while (i + 1 < message.size() && message[i + 1] == ' ') ++i;  // the next line's indent
      if (i + 1 < message.size()) out += "; ";
    } else if (c == '\t') {
      out += ' ';
    } else if (c < 0x20 || c >= 0x7f) {
      char hex[5];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    } else {
      out += char(c);
    }
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

Flag front_background_flag() {
  return {"front-background", true,
          "F  the front camera's empty scene (a clean plate, same size): the head is cut out by "
          "difference, which holds in front of a cluttered room"};
}

Flag side_background_flag() {
  return {"side-background", true, "F  the side camera's empty scene (clean plate)"};
}

}  // namespace orthoface::app
