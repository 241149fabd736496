// write_glb: binary glTF 2.0 (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html),
// serialised by tinygltf (Debian libtinygltf-dev).
#include <tiny_gltf.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "render/textured_export.h"

namespace orthoface::render {
namespace {

// Unit normals welded over coincident positions, so a UV seam shades smoothly.
std::vector<Eigen::Vector3d> welded_normals(const mesh::TriMesh& m) {
  std::map<std::array<double, 3>, Eigen::Vector3d> by_position;
  auto key = [&](int v) {
    return std::array<double, 3>{m.vertices[v].x(), m.vertices[v].y(), m.vertices[v].z()};
  };
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d n =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    for (int k = 0; k < 3; ++k) {
      auto [it, fresh] = by_position.try_emplace(key(t[k]), Eigen::Vector3d::Zero());
      it->second += n;
    }
  }
  std::vector<Eigen::Vector3d> out;
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    auto it = by_position.find(key(int(v)));
    const Eigen::Vector3d n = it == by_position.end() ? Eigen::Vector3d::Zero() : it->second;
    out.push_back(n.norm() > 0 ? n.normalized() : Eigen::Vector3d(0, 0, 1));
  }
  return out;
}

// Appends `bytes` of `data` to buffer 0 as a new buffer view (4-byte aligned); returns its index.
int add_view(tinygltf::Model& g, const void* data, size_t bytes, int target) {
  std::vector<unsigned char>& bin = g.buffers[0].data;
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = bin.size();
  view.byteLength = bytes;
  view.target = target;
  const auto* p = static_cast<const unsigned char*>(data);
  bin.insert(bin.end(), p, p + bytes);
  while (bin.size() % 4) bin.push_back(0);
  g.bufferViews.push_back(view);
  return int(g.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& g, int view, int component, size_t count, int type) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.componentType = component;
  a.count = count;
  a.type = type;
  g.accessors.push_back(a);
  return int(g.accessors.size()) - 1;
}

}  // namespace

void write_glb(const mesh::TriMesh& m, const std::string& path) {
  mesh::check_mesh(m, "write_glb: mesh");
  if (m.uvs.empty() || m.texture.empty())
    throw std::invalid_argument("write_glb: the mesh has no uvs / texture to embed");
  std::vector<float> pos, nrm, uv;
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  const auto normals = welded_normals(m);
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    const Eigen::Vector3f p = (m.vertices[v] / 1000.0).cast<float>();  // mm -> m
    pos.insert(pos.end(), {p.x(), p.y(), p.z()});
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    nrm.insert(nrm.end(), {float(normals[v].x()), float(normals[v].y()), float(normals[v].z())});
    uv.insert(uv.end(), {float(m.uvs[v].x()), float(1.0 - m.uvs[v].y())});  // glTF: v down
  }
  std::vector<uint8_t> png;
  if (!cv::imencode(".png", m.texture, png))
    throw std::runtime_error("write_glb: cannot encode the texture of " + path);
  tinygltf::Model g;
  g.asset.version = "2.0";
  g.asset.generator = "orthoface";
  g.buffers.resize(1);
  const int p =
      add_accessor(g, add_view(g, pos.data(), pos.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, m.vertices.size(), TINYGLTF_TYPE_VEC3);
  g.accessors[p].minValues = {lo.x(), lo.y(), lo.z()};
  g.accessors[p].maxValues = {hi.x(), hi.y(), hi.z()};
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.material = 0;
  prim.attributes["POSITION"] = p;
  prim.attributes["NORMAL"] =
      add_accessor(g, add_view(g, nrm.data(), nrm.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, m.vertices.size(), TINYGLTF_TYPE_VEC3);
  prim.attributes["TEXCOORD_0"] =
      add_accessor(g, add_view(g, uv.data(), uv.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, m.vertices.size(), TINYGLTF_TYPE_VEC2);
  prim.indices = add_accessor(g,
                              add_view(g, m.triangles.data(), m.triangles.size() * 12,
                                       TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                              TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, m.triangles.size() * 3,
                              TINYGLTF_TYPE_SCALAR);
  tinygltf::Image image;
  image.bufferView = add_view(g, png.data(), png.size(), 0);
  image.mimeType = "image/png";
  g.images.push_back(image);
  tinygltf::Sampler sampler;
  sampler.magFilter = sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.wrapS = sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  g.samplers.push_back(sampler);
  tinygltf::Texture texture;
  texture.source = 0;
  texture.sampler = 0;
  g.textures.push_back(texture);
  tinygltf::Material material;
  material.name = "inherited";
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  material.pbrMetallicRoughness.metallicFactor = 0;
  material.pbrMetallicRoughness.roughnessFactor = 1;
  g.materials.push_back(material);
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(prim);
  g.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  node.name = "head";
  g.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  g.scenes.push_back(scene);
  g.defaultScene = 0;
  io::write_stream_atomically(path, [&](std::ostream& f) {
    if (!tinygltf::TinyGLTF().WriteGltfSceneToStream(&g, f, false, true))
      throw std::runtime_error("cannot serialise the glTF");
  });
}

}  // namespace orthoface::render
