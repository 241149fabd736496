// vision::read_image, the loader every photo goes through: the first byte picks the extension
// (.png, .jpg, .bmp), the rest is the file.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz/fuzz_input.h"
#include "vision/image_prep.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* const kNames[] = {"input.png", "input.jpg", "input.bmp"};
  try {
    orthoface::vision::read_image(
        orthoface::fuzz::as_file(data + 1, size - 1, kNames[data[0] % 3]));
  } catch (const std::exception&) {
  }
  return 0;
}
