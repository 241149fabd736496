// capture::read_rig: our rig YAML and OpenCV stereo calibration files (YAML or XML), read by
// capture/rig_text.h.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "capture/camera_model.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    orthoface::capture::read_rig(orthoface::fuzz::as_file(data, size, "rig.yaml"));
  } catch (const std::exception&) {
  }
  return 0;
}
