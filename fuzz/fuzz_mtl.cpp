// The OBJ reader's material file: a fixed textured OBJ naming input.mtl, the fuzz input as that
// MTL (texture paths in it are read as the OBJ reader would).
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

#include "fuzz/fuzz_input.h"
#include "mesh/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string obj = [] {
    const std::string text =
        "mtllib input.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "usemtl skin\nf 1/1 2/2 3/3\n";
    return orthoface::fuzz::as_file(reinterpret_cast<const uint8_t*>(text.data()), text.size(),
                                    "input.obj");
  }();
  orthoface::fuzz::as_file(data, size, "input.mtl");
  try {
    orthoface::mesh::read_mesh(obj);
  } catch (const std::exception&) {
  }
  return 0;
}
