#pragma once
// The report every accuracy run of bench/ ends with: JSON on stdout, the Markdown table on
// stderr, and both as OUT_DIR/<stem>.json and <stem>.md when an output folder is given.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
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

// NaN when empty.
inline double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}

// Throws std::runtime_error naming the file that could not be written.
inline void write_report(const std::string& out_dir, const std::string& stem,
                         const nlohmann::json& j, const std::string& md) {
  if (!out_dir.empty()) {
    for (const auto& [name, text] : {std::pair{out_dir + "/" + stem + ".md", md},
                                     std::pair{out_dir + "/" + stem + ".json", j.dump(2) + "\n"}}) {
      std::ofstream f(name);
      if (!(f << text)) throw std::runtime_error("cannot write " + name);
    }
  }
  std::cout << j.dump(2) << "\n";
  std::cerr << md;
}

}  // namespace orthoface::bench
