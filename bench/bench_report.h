#pragma once
// The report every accuracy run of bench/ ends with: JSON on stdout, the Markdown table on
// stderr, and both as OUT_DIR/<stem>.json and <stem>.md when an output folder is given.

#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace orthoface::bench {

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
