#include "vision/tfjs_weights.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace orthoface::vision {

std::map<std::string, NetWeight> read_tfjs_weights(const std::string& model_dir,
                                                   const std::string& manifest_file,
                                                   const std::string& bin_file,
                                                   const std::string& what) {
  namespace fs = std::filesystem;
  const fs::path manifest_path = fs::path(model_dir) / manifest_file;
  const fs::path bin_path = fs::path(model_dir) / bin_file;
  std::ifstream mf(manifest_path);
  if (!mf) throw std::runtime_error(what + ": cannot read " + manifest_path.string());
  std::ifstream bf(bin_path, std::ios::binary);
  if (!bf) throw std::runtime_error(what + ": cannot read " + bin_path.string());
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(bf)),
                                        std::istreambuf_iterator<char>());
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(mf);
  } catch (const std::exception& e) {
    throw std::runtime_error(what + ": " + manifest_path.string() + " is not JSON: " + e.what());
  }
  // Weights in manifest order, each 8-bit quantised (value = q * scale + min) or float32.
  std::map<std::string, NetWeight> out;
  size_t offset = 0;
  try {
    for (const auto& group : manifest)
      for (const auto& entry : group.at("weights")) {
        NetWeight t;
        size_t n = 1;
        for (const auto& d : entry.at("shape"))
          t.shape.push_back(d.get<int>()), n *= size_t(t.shape.back());
        t.v.resize(n);
        if (entry.contains("quantization")) {
          const auto& q = entry.at("quantization");
          if (q.at("dtype") != "uint8") throw std::runtime_error("unsupported quantisation");
          const double scale = q.at("scale"), min = q.at("min");
          if (offset + n > bytes.size()) throw std::runtime_error("weights end early");
          for (size_t k = 0; k < n; ++k) t.v[k] = float(bytes[offset + k] * scale + min);
          offset += n;
        } else {
          if (offset + 4 * n > bytes.size()) throw std::runtime_error("weights end early");
          std::copy_n(reinterpret_cast<const float*>(bytes.data() + offset), n, t.v.data());
          offset += 4 * n;
        }
        out[entry.at("name").get<std::string>()] = std::move(t);
      }
  } catch (const std::exception& e) {
    throw std::runtime_error(what + ": " + bin_path.string() + " does not match " +
                             manifest_path.string() + ": " + e.what());
  }
  return out;
}

}  // namespace orthoface::vision
