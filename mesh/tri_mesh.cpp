#include "mesh/tri_mesh.h"

#include <stdexcept>

namespace orthoface::mesh {

void check_mesh(const TriMesh& mesh, const std::string& what) {
  auto fail = [&](const std::string& msg) { throw std::invalid_argument(what + ": " + msg); };
  if (mesh.vertices.empty() || mesh.triangles.empty()) fail("mesh has no triangles");
  for (size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite()) fail("vertex " + std::to_string(i) + " is not finite");
  const int n = static_cast<int>(mesh.vertices.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (f[k] < 0 || f[k] >= n)
        fail("triangle " + std::to_string(t) + " has vertex index " + std::to_string(f[k]) +
             " out of range [0, " + std::to_string(n) + ")");
    if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
      fail("triangle " + std::to_string(t) + " repeats a vertex");
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.vertices.size())
    fail("uvs has " + std::to_string(mesh.uvs.size()) + " entries for " + std::to_string(n) +
         " vertices");
  if (!mesh.colors.empty() && mesh.colors.size() != mesh.vertices.size())
    fail("colors has " + std::to_string(mesh.colors.size()) + " entries for " + std::to_string(n) +
         " vertices");
  if (!mesh.texture.empty() && mesh.texture.type() != CV_8UC3)
    fail("texture must be 8-bit BGR, got OpenCV type " + std::to_string(mesh.texture.type()));
}

}  // namespace orthoface::mesh
