// The mesh readers (mesh::read_mesh) on one format, chosen at build time by FUZZ_EXTENSION
// (".obj", ".ply", ".off", ".gltf", ".glb"). A thrown std::exception is the reader refusing the
// file, which is right; a crash, a hang or a sanitizer report is a defect.
#include <cstddef>
#include <cstdint>
#include <exception>

#include "fuzz/fuzz_input.h"
#include "mesh/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    orthoface::mesh::read_mesh(orthoface::fuzz::as_file(data, size, "input" FUZZ_EXTENSION));
  } catch (const std::exception&) {
  }
  return 0;
}
