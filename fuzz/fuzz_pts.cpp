// vision::read_pts: iBUG 68-point landmark files.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz/fuzz_input.h"
#include "vision/pts_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    orthoface::vision::read_pts(orthoface::fuzz::as_file(data, size, "input.pts"));
  } catch (const std::exception&) {
  }
  return 0;
}
