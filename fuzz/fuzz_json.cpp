// The JSON readers: vision::read_observation (observation.json) and
// analysis::read_feature_points (features.json / FP.json), each given every input.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "analysis/motion_areas.h"
#include "fuzz/fuzz_input.h"
#include "vision/observation_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = orthoface::fuzz::as_file(data, size, "input.json");
  try {
    orthoface::vision::read_observation(path);
  } catch (const std::exception&) {
  }
  try {
    orthoface::analysis::read_feature_points(path);
  } catch (const std::exception&) {
  }
  return 0;
}
