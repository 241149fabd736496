// glTF 2.0 reading (.glb and .gltf with external or data-URI buffers and images) through
// tinygltf (Debian libtinygltf-dev): it parses the container, the JSON and the URIs; this file
// walks the scene and decodes accessors with every range checked, since tinygltf leaves
// accessor / buffer-view bounds to the caller.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "io/image_file.h"
#include "mesh/mesh_io_detail.h"

namespace orthoface::mesh::io {

namespace {

constexpr int kMaxNodeDepth = 1000;  // deeper hierarchies are refused, not recursed into

// A number read from the file, for a message: any double (NaN, huge) prints.
std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.17g", v);
  return text;
}

// tinygltf's file access, kept to regular files (no devices, no ~ or $VAR expansion).
bool file_exists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}
std::string expand_path(const std::string& path, void*) { return path; }
bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void*) {
  try {
    const std::string bytes = read_bytes(path);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const std::exception& e) {
    if (err) *err += e.what();
    return false;
  }
}
bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not allowed while reading";
  return false;
}

// Images are kept as their encoded bytes; only the base colour texture is decoded (OpenCV).
bool keep_encoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                  const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

class Scene {
 public:
  Scene(const tinygltf::Model& model, const std::string& path, const MeshReadOptions& options)
      : g_(model), path_(path), options_(options) {}

  TriMesh mesh() {
    TriMesh m;
    if (!g_.scenes.empty() && !g_.nodes.empty()) {
      const int s = g_.defaultScene >= 0 ? g_.defaultScene : 0;
      check_index(s, g_.scenes.size(), "scenes");
      std::vector<char> on_path(g_.nodes.size(), 0);
      for (int n : g_.scenes[s].nodes) visit(m, n, Eigen::Matrix4d::Identity(), on_path, 0);
    } else {
      for (size_t k = 0; k < g_.meshes.size(); ++k)
        add_mesh(m, static_cast<int>(k), Eigen::Matrix4d::Identity());
    }
    if (!any_uv_) m.uvs.clear();
    if (!any_color_) m.colors.clear();
    if (options_.load_texture && !m.uvs.empty()) {
      if (!options_.texture_path.empty())
        m.texture = load_texture(options_.texture_path, path_);
      else if (texture_image_ >= 0)
        m.texture = image(texture_image_);
    }
    return m;
  }

 private:
  void check_index(int index, size_t size, const char* array) const {
    if (index < 0 || static_cast<size_t>(index) >= size)
      fail(path_, std::string("reference to ") + array + "[" + std::to_string(index) +
                      "] which does not exist");
  }

  void visit(TriMesh& m, int n, const Eigen::Matrix4d& parent, std::vector<char>& on_path,
             int depth) {
    check_index(n, g_.nodes.size(), "nodes");
    if (on_path[n]) fail(path_, "node " + std::to_string(n) + " is its own ancestor");
    if (depth > kMaxNodeDepth)
      fail(path_, "node hierarchy deeper than " + std::to_string(kMaxNodeDepth));
    const tinygltf::Node& node = g_.nodes[n];
    const Eigen::Matrix4d world = parent * local(node);
    if (node.mesh >= 0) add_mesh(m, node.mesh, world);
    on_path[n] = 1;
    for (int c : node.children) visit(m, c, world, on_path, depth + 1);
    on_path[n] = 0;
  }

  static Eigen::Matrix4d local(const tinygltf::Node& node) {
    if (node.matrix.size() == 16)
      return Eigen::Map<const Eigen::Matrix4d>(node.matrix.data());  // column-major
    Eigen::Affine3d a = Eigen::Affine3d::Identity();
    const auto& t = node.translation;
    if (t.size() == 3) a.translate(Eigen::Vector3d(t[0], t[1], t[2]));
    const auto& q = node.rotation;  // x y z w
    if (q.size() == 4) a.rotate(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized());
    const auto& s = node.scale;
    if (s.size() == 3) a.scale(Eigen::Vector3d(s[0], s[1], s[2]));
    return a.matrix();
  }

  // Accessor values as doubles, `comps` per element (normalized integers mapped to [0, 1] or
  // [-1, 1]). Every offset, stride and count is checked against its view and buffer without
  // overflow.
  std::vector<double> accessor(int index, int& comps) const {
    check_index(index, g_.accessors.size(), "accessors");
    const tinygltf::Accessor& a = g_.accessors[index];
    const std::string what = "accessor " + std::to_string(index);
    if (a.sparse.isSparse) fail(path_, "sparse accessors are not supported");
    comps = a.type == TINYGLTF_TYPE_SCALAR ? 1
            : a.type == TINYGLTF_TYPE_VEC2 ? 2
            : a.type == TINYGLTF_TYPE_VEC3 ? 3
            : a.type == TINYGLTF_TYPE_VEC4 ? 4
                                           : 0;
    if (comps == 0) fail(path_, what + " has unsupported type");
    const int ct = a.componentType;
    const int size = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(ct));
    if (size <= 0 || ct == TINYGLTF_COMPONENT_TYPE_DOUBLE || ct == TINYGLTF_COMPONENT_TYPE_INT)
      fail(path_, what + " has unsupported componentType " + std::to_string(ct));
    check_index(a.bufferView, g_.bufferViews.size(), "bufferViews");
    const tinygltf::BufferView& view = g_.bufferViews[a.bufferView];
    check_index(view.buffer, g_.buffers.size(), "buffers");
    const std::vector<unsigned char>& buf = g_.buffers[view.buffer].data;
    const size_t element = size_t(size) * comps;
    const size_t stride = view.byteStride ? view.byteStride : element;
    const size_t count = a.count;
    // The view must lie inside its buffer and the accessor inside its view.
    if (view.byteOffset > buf.size() || view.byteLength > buf.size() - view.byteOffset)
      fail(path_, "buffer view " + std::to_string(a.bufferView) +
                      " lies past the end of its buffer (truncated file?)");
    if (stride < element) fail(path_, what + " has a byteStride smaller than its element");
    const size_t room = view.byteLength;
    if (count > 0 && (a.byteOffset > room || element > room - a.byteOffset ||
                      (count - 1) > (room - a.byteOffset - element) / stride))
      fail(path_, what + " reads past the end of its buffer view (truncated file?)");
    const unsigned char* base = buf.data() + view.byteOffset + a.byteOffset;
    const bool norm = a.normalized;
    std::vector<double> out(count * comps);
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < comps; ++c)
        out[i * comps + c] = component(base + i * stride + size_t(c) * size, ct, norm);
    return out;
  }

  static double component(const unsigned char* p, int ct, bool norm) {
    auto read = [p](auto v) {
      std::memcpy(&v, p, sizeof(v));
      return v;
    };
    switch (ct) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return read(float{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return norm ? read(std::uint32_t{}) / 4294967295.0 : read(std::uint32_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return norm ? read(std::uint16_t{}) / 65535.0 : read(std::uint16_t{});
      case TINYGLTF_COMPONENT_TYPE_SHORT:
        return norm ? std::max(read(std::int16_t{}) / 32767.0, -1.0) : read(std::int16_t{});
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return norm ? read(std::uint8_t{}) / 255.0 : read(std::uint8_t{});
      default:  // BYTE
        return norm ? std::max(read(std::int8_t{}) / 127.0, -1.0) : read(std::int8_t{});
    }
  }

  void add_mesh(TriMesh& m, int mesh_index, const Eigen::Matrix4d& world) {
    check_index(mesh_index, g_.meshes.size(), "meshes");
    for (const tinygltf::Primitive& prim : g_.meshes[mesh_index].primitives) {
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES)
        fail(path_,
             "primitive mode " + std::to_string(mode) + " is not supported (triangles only)");
      const auto attr = [&](const char* name) {
        const auto it = prim.attributes.find(name);
        return it == prim.attributes.end() ? -1 : it->second;
      };
      if (attr("POSITION") < 0) fail(path_, "a primitive has no POSITION attribute");
      int c = 0;
      const std::vector<double> pos = accessor(attr("POSITION"), c);
      if (c != 3) fail(path_, "POSITION must be VEC3");
      const size_t n = pos.size() / 3, base = m.vertices.size();
      if (base + n > size_t(std::numeric_limits<int>::max()))
        fail(path_, "more vertices than a mesh can index");
      std::vector<double> uv, col;
      int cu = 0, cc = 0;
      if (attr("TEXCOORD_0") >= 0) uv = accessor(attr("TEXCOORD_0"), cu);
      if (attr("COLOR_0") >= 0) col = accessor(attr("COLOR_0"), cc);
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector4d p =
            world * Eigen::Vector4d(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2], 1);
        m.vertices.push_back(p.head<3>());
        Eigen::Vector2d t(0, 0);
        if (cu == 2 && uv.size() >= 2 * (i + 1)) {
          t = Eigen::Vector2d(uv[2 * i], uv[2 * i + 1]);
          if (!options_.gltf_uv_bottom_origin) t.y() = 1 - t.y();  // glTF v = 0 is the top row
        }
        m.uvs.push_back(t);
        m.colors.push_back(cc >= 3 && col.size() >= cc * (i + 1)
                               ? Eigen::Vector3d(col[cc * i], col[cc * i + 1], col[cc * i + 2])
                               : Eigen::Vector3d(1, 1, 1));
      }
      any_uv_ |= cu == 2;
      any_color_ |= cc >= 3;
      std::vector<double> idx;
      if (prim.indices >= 0) {
        int ci = 0;
        idx = accessor(prim.indices, ci);
      } else {
        for (size_t i = 0; i < n; ++i) idx.push_back(static_cast<double>(i));
      }
      if (idx.size() % 3)
        fail(path_, "index count " + std::to_string(idx.size()) + " is not a multiple of 3");
      for (size_t k = 0; k < idx.size(); k += 3) {
        std::array<int, 3> t;
        for (int q = 0; q < 3; ++q) {
          if (!(idx[k + q] >= 0 && idx[k + q] < double(n)))
            fail(path_, "index " + number_text(idx[k + q]) + " out of range (" + std::to_string(n) +
                            " vertices)");
          t[q] = static_cast<int>(base + size_t(idx[k + q]));
        }
        m.triangles.push_back(t);
      }
      if (texture_image_ < 0 && prim.material >= 0)
        texture_image_ = base_color_image(prim.material);
    }
  }

  int base_color_image(int material) const {
    check_index(material, g_.materials.size(), "materials");
    const int tex = g_.materials[material].pbrMetallicRoughness.baseColorTexture.index;
    if (tex < 0) return -1;
    check_index(tex, g_.textures.size(), "textures");
    return g_.textures[tex].source;
  }

  cv::Mat image(int index) const {
    check_index(index, g_.images.size(), "images");
    const std::vector<unsigned char>& bytes = g_.images[index].image;
    cv::Mat out;
    if (!bytes.empty() && bytes.size() < size_t(std::numeric_limits<int>::max()))
      out = orthoface::io::imdecode_accepted(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U,
                                                     const_cast<unsigned char*>(bytes.data())),
                                             cv::IMREAD_COLOR);
    if (out.empty()) fail(path_, "image " + std::to_string(index) + " cannot be decoded");
    return out;
  }

  const tinygltf::Model& g_;
  std::string path_;
  MeshReadOptions options_;
  bool any_uv_ = false, any_color_ = false;
  int texture_image_ = -1;
};

}  // namespace

TriMesh read_gltf(const std::string& path, const MeshReadOptions& options) {
  const std::string bytes = read_bytes(path);
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) fail(path, "file too large");
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks({file_exists, expand_path, read_whole_file, refuse_write, nullptr});
  loader.SetImageLoader(keep_encoded, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string dir = std::filesystem::path(path).parent_path().string();
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const bool binary = bytes.compare(0, 4, "glTF") == 0;
  const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data,
                                                       static_cast<unsigned int>(bytes.size()), dir)
                         : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                                      static_cast<unsigned int>(bytes.size()), dir);
  if (!ok) {
    while (!err.empty() && std::isspace(static_cast<unsigned char>(err.back()))) err.pop_back();
    std::replace(err.begin(), err.end(), '\n', ' ');
    fail(path, std::string(binary ? "invalid GLB: " : "invalid glTF: ") +
                   (err.empty() ? "cannot be parsed" : err));
  }
  TriMesh m = Scene(model, path, options).mesh();
  if (m.triangles.empty()) fail(path, "no triangles in any mesh");
  validate_read(m, path);
  return m;
}

}  // namespace orthoface::mesh::io
