#pragma once
// The report every accuracy run of bench/ ends with: JSON on stdout, the Markdown table on
// stderr, and both as OUT_DIR/<stem>.json and <stem>.md when an output folder is given.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace orthoface::bench {

// The middle value (the upper of the two middle ones for an even count); NaN when empty.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// "a,b,c" -> {"a", "b", "c"}: the benchmarks' --people / --kinds lists.
inline std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string x; std::getline(ss, x, ',');) out.push_back(x);
  return out;
}

// NaN when empty.
inline double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}

// Creates the output folder (and its parents) before a long run, so that a folder that cannot be
// made fails at once rather than after the measurements. Nothing for an empty name.
inline void make_out_dir(const std::string& out_dir) {
  if (out_dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir))
    throw std::runtime_error("cannot create the output folder " + out_dir +
                             (ec ? ": " + ec.message() : ""));
}

// Throws std::runtime_error naming the file that could not be written. Each file is written
// whole under a temporary name and then renamed, so a failed run leaves no half report.
inline void write_report(const std::string& out_dir, const std::string& stem,
                         const nlohmann::json& j, const std::string& md) {
  if (!out_dir.empty()) {
    make_out_dir(out_dir);
    for (const auto& [name, text] : {std::pair{out_dir + "/" + stem + ".md", md},
                                     std::pair{out_dir + "/" + stem + ".json", j.dump(2) + "\n"}}) {
      const std::string part = name + ".part";
      {
        std::ofstream f(part);
        if (!(f << text) || !(f.flush())) throw std::runtime_error("cannot write " + name);
      }
      std::error_code ec;
      std::filesystem::rename(part, name, ec);
      if (ec) {
        std::filesystem::remove(part, ec);
        throw std::runtime_error("cannot write " + name);
      }
    }
  }
  std::cout << j.dump(2) << "\n";
  std::cerr << md;
}

}  // namespace orthoface::bench
