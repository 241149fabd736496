// write_glb: binary glTF 2.0 (https://registry.khronos.org/glTF/specs/2.0/glTF-2.0.html).
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

void append(std::vector<uint8_t>& bin, const void* data, size_t bytes) {
  const auto* p = static_cast<const uint8_t*>(data);
  bin.insert(bin.end(), p, p + bytes);
  while (bin.size() % 4) bin.push_back(0);  // every view starts 4-byte aligned
}

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

struct View {
  size_t offset, length;
  int target;  // 0 = none (image)
};

std::string gltf_json(const mesh::TriMesh& m, const std::vector<View>& views, size_t bin_size,
                      const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  std::ostringstream j;
  j.precision(9);
  const size_t n = m.vertices.size();
  j << R"({"asset":{"version":"2.0","generator":"orthoface"},"scene":0,"scenes":[{"nodes":[0]}],)"
    << R"("nodes":[{"mesh":0,"name":"head"}],)"
    << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2},)"
    << R"("indices":3,"material":0}]}],)"
    << R"("materials":[{"name":"inherited","pbrMetallicRoughness":{"baseColorTexture":{"index":0},)"
    << R"("metallicFactor":0,"roughnessFactor":1}}],)"
    << R"("textures":[{"source":0,"sampler":0}],)"
    << R"("samplers":[{"magFilter":9729,"minFilter":9729,"wrapS":33071,"wrapT":33071}],)"
    << R"("images":[{"bufferView":4,"mimeType":"image/png"}],)"
    << R"("accessors":[)"
    << R"({"bufferView":0,"componentType":5126,"count":)" << n << R"(,"type":"VEC3","min":[)"
    << lo.x() << "," << lo.y() << "," << lo.z() << "],\"max\":[" << hi.x() << "," << hi.y() << ","
    << hi.z() << "]},"
    << R"({"bufferView":1,"componentType":5126,"count":)" << n << R"(,"type":"VEC3"},)"
    << R"({"bufferView":2,"componentType":5126,"count":)" << n << R"(,"type":"VEC2"},)"
    << R"({"bufferView":3,"componentType":5125,"count":)" << m.triangles.size() * 3
    << R"(,"type":"SCALAR"}],"bufferViews":[)";
  for (size_t i = 0; i < views.size(); ++i) {
    j << (i ? "," : "") << R"({"buffer":0,"byteOffset":)" << views[i].offset << R"(,"byteLength":)"
      << views[i].length;
    if (views[i].target) j << R"(,"target":)" << views[i].target;
    j << "}";
  }
  j << R"(],"buffers":[{"byteLength":)" << bin_size << "}]}";
  return j.str();
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
  std::vector<uint8_t> bin;
  std::vector<View> views;
  auto add = [&](const void* data, size_t bytes, int target) {
    views.push_back({bin.size(), bytes, target});
    append(bin, data, bytes);
  };
  add(pos.data(), pos.size() * 4, 34962);
  add(nrm.data(), nrm.size() * 4, 34962);
  add(uv.data(), uv.size() * 4, 34962);
  add(m.triangles.data(), m.triangles.size() * 12, 34963);
  add(png.data(), png.size(), 0);
  std::string json = gltf_json(m, views, bin.size(), lo, hi);
  while (json.size() % 4) json.push_back(' ');
  const uint32_t header[3] = {0x46546C67u, 2u, uint32_t(12 + 8 + json.size() + 8 + bin.size())};
  const uint32_t json_head[2] = {uint32_t(json.size()), 0x4E4F534Au};
  const uint32_t bin_head[2] = {uint32_t(bin.size()), 0x004E4942u};
  io::write_stream_atomically(path, [&](std::ostream& f) {
    f.write(reinterpret_cast<const char*>(header), 12);
    f.write(reinterpret_cast<const char*>(json_head), 8);
    f.write(json.data(), std::streamsize(json.size()));
    f.write(reinterpret_cast<const char*>(bin_head), 8);
    f.write(reinterpret_cast<const char*>(bin.data()), std::streamsize(bin.size()));
  });
}

}  // namespace orthoface::render
