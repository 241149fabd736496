#pragma once
// Weights of a trained network in TensorFlow.js's layers format (a JSON manifest naming each
// weight's shape and, when quantised, its 8-bit scale; one binary file of the values in manifest
// order): the format the MIT-licensed face-api.js models ship in (vision/models/README.md).

#include <map>
#include <string>
#include <vector>

namespace orthoface::vision {

struct NetWeight {
  std::vector<int> shape;  // e.g. [kh, kw, in, out] for a convolution's filters
  std::vector<float> v;    // row-major over `shape`
};

// Reads `manifest_file` and `bin_file` in `model_dir`. Throws std::runtime_error that starts with
// `what` and names the file when either cannot be read, the manifest is not JSON, uses another
// quantisation than uint8, or the binary ends before the manifest's weights do.
std::map<std::string, NetWeight> read_tfjs_weights(const std::string& model_dir,
                                                   const std::string& manifest_file,
                                                   const std::string& bin_file,
                                                   const std::string& what);

}  // namespace orthoface::vision
