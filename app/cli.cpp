#include "app/cli.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>

namespace orthoface::app {

std::string Args::get(const std::string& flag, const std::string& fallback) const {
  auto it = values.find(flag);
  return it == values.end() ? fallback : it->second;
}

Args parse_args(const Command& command, int argc, char** argv) {
  Args args;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      args.help = true;
      continue;
    }
    if (a.rfind("--", 0) == 0 && a.size() > 2) {
      std::string name = a.substr(2), value;
      bool inline_value = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        inline_value = true;
      }
      const Flag* flag = nullptr;
      for (const Flag& f : command.flags)
        if (f.name == name) flag = &f;
      if (!flag)
        throw std::invalid_argument(command.name + ": unknown flag --" + name + " (see orthoface " +
                                    command.name + " --help)");
      if (flag->takes_value && !inline_value) {
        if (i + 1 >= argc)
          throw std::invalid_argument(command.name + ": flag --" + name + " needs a value");
        value = argv[++i];
      } else if (!flag->takes_value && inline_value) {
        throw std::invalid_argument(command.name + ": flag --" + name + " takes no value");
      }
      if (args.values.count(name))
        throw std::invalid_argument(command.name + ": flag --" + name + " given twice");
      args.values[name] = value;
      continue;
    }
    if (a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])) &&
        a[1] != '.') {
      // Short flags: only -o is used, as an alias of --output / -o FILE.
      const Flag* flag = nullptr;
      for (const Flag& f : command.flags)
        if (f.name == a.substr(1)) flag = &f;
      if (!flag) throw std::invalid_argument(command.name + ": unknown flag " + a);
      if (i + 1 >= argc)
        throw std::invalid_argument(command.name + ": flag " + a + " needs a value");
      args.values[flag->name] = argv[++i];
      continue;
    }
    if (static_cast<int>(args.positional.size()) >= command.max_positional)
      throw std::invalid_argument(command.name + ": unexpected argument '" + a + "'");
    args.positional.push_back(a);
  }
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

void prepare_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw std::runtime_error("output folder: empty path");
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw std::runtime_error("output folder " + dir + ": exists and is not a folder");
  fs::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("output folder " + dir + ": cannot create (" + ec.message() + ")");
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

}  // namespace orthoface::app
