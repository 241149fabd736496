// glTF 2.0 reading: binary .glb and .gltf with external or data-URI buffers and images.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "mesh/mesh_io_detail.h"

namespace orthoface::mesh::io {

namespace {

using nlohmann::json;

std::string base64_decode(const std::string& s, const std::string& path) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;
    if (c == '/' || c == '_') return 63;
    return -1;
  };
  std::string out;
  int acc = 0, bits = 0;
  for (char c : s) {
    if (c == '=' || std::isspace(static_cast<unsigned char>(c))) continue;
    const int v = val(c);
    if (v < 0) fail(path, "bad base64 data in a data URI");
    acc = (acc << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((acc >> bits) & 0xff));
    }
  }
  return out;
}

std::uint32_t le32(const std::string& b, size_t at) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

// Bytes behind a "uri": a data URI or a file next to the glTF file.
std::string uri_bytes(const std::string& uri, const std::string& path) {
  if (uri.rfind("data:", 0) == 0) {
    const size_t comma = uri.find(',');
    if (comma == std::string::npos || uri.find(";base64") > comma)
      fail(path, "unsupported data URI");
    return base64_decode(uri.substr(comma + 1), path);
  }
  return read_bytes((std::filesystem::path(path).parent_path() / uri).string());
}

class Gltf {
 public:
  Gltf(const std::string& path, const MeshReadOptions& options) : path_(path), options_(options) {
    const std::string bytes = read_bytes(path);
    std::string bin;
    if (bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0) {
      if (bytes.size() < 20) fail(path, "truncated GLB header");
      if (le32(bytes, 4) != 2)
        fail(path, "GLB version " + std::to_string(le32(bytes, 4)) + " (only 2 is supported)");
      if (le32(bytes, 8) > bytes.size())
        fail(path, "truncated GLB (header says " + std::to_string(le32(bytes, 8)) + " bytes)");
      const std::uint32_t jlen = le32(bytes, 12);
      if (le32(bytes, 16) != 0x4E4F534Au || 20ull + jlen > bytes.size())
        fail(path, "GLB has no valid JSON chunk");
      parse(bytes.substr(20, jlen));
      const size_t b = 20 + ((jlen + 3) & ~3u);
      if (b + 8 <= bytes.size() && le32(bytes, b + 4) == 0x004E4942u) {
        const std::uint32_t blen = le32(bytes, b);
        if (b + 8 + blen > bytes.size()) fail(path, "truncated GLB binary chunk");
        bin = bytes.substr(b + 8, blen);
      }
    } else {
      parse(bytes);
    }
    for (const auto& b : j_.value("buffers", json::array())) {
      buffers_.push_back(b.contains("uri") ? uri_bytes(b["uri"].get<std::string>(), path) : bin);
      if (buffers_.back().size() < b.value("byteLength", size_t{0}))
        fail(path,
             "buffer " + std::to_string(buffers_.size() - 1) + " is shorter than its byteLength");
    }
  }

  TriMesh mesh() {
    TriMesh m;
    std::function<void(int, const Eigen::Matrix4d&)> visit = [&](int n,
                                                                 const Eigen::Matrix4d& parent) {
      const json& node = at("nodes", n);
      const Eigen::Matrix4d world = parent * local(node);
      if (node.contains("mesh")) add_mesh(m, node["mesh"].get<int>(), world);
      for (const auto& c : node.value("children", json::array())) visit(c.get<int>(), world);
    };
    if (j_.contains("scenes") && j_.contains("nodes")) {
      for (const auto& n : at("scenes", j_.value("scene", 0)).value("nodes", json::array()))
        visit(n.get<int>(), Eigen::Matrix4d::Identity());
    } else {
      for (size_t k = 0; k < j_.value("meshes", json::array()).size(); ++k)
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
  void parse(const std::string& text) {
    try {
      j_ = json::parse(text);
    } catch (const json::exception& e) {
      fail(path_, std::string("invalid glTF JSON: ") + e.what());
    }
    if (!j_.is_object()) fail(path_, "glTF JSON is not an object");
  }

  const json& at(const char* array, int index) const {
    if (!j_.contains(array) || !j_[array].is_array() || index < 0 ||
        index >= static_cast<int>(j_[array].size()))
      fail(path_, std::string("reference to ") + array + "[" + std::to_string(index) +
                      "] which does not exist");
    return j_[array][index];
  }

  static Eigen::Matrix4d local(const json& node) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (node.contains("matrix")) {
      const auto v = node["matrix"].get<std::vector<double>>();
      if (v.size() == 16) m = Eigen::Map<const Eigen::Matrix4d>(v.data());  // column-major
      return m;
    }
    Eigen::Affine3d a = Eigen::Affine3d::Identity();
    if (node.contains("translation")) {
      const auto t = node["translation"].get<std::vector<double>>();
      if (t.size() == 3) a.translate(Eigen::Vector3d(t[0], t[1], t[2]));
    }
    if (node.contains("rotation")) {
      const auto q = node["rotation"].get<std::vector<double>>();  // x y z w
      if (q.size() == 4) a.rotate(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized());
    }
    if (node.contains("scale")) {
      const auto s = node["scale"].get<std::vector<double>>();
      if (s.size() == 3) a.scale(Eigen::Vector3d(s[0], s[1], s[2]));
    }
    return a.matrix();
  }

  // Accessor values as doubles, `comps` per element (normalized integers mapped to [0, 1]).
  std::vector<double> accessor(int index, int& comps) const {
    const json& a = at("accessors", index);
    if (a.contains("sparse")) fail(path_, "sparse accessors are not supported");
    static const std::map<std::string, int> ncomp = {
        {"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4}};
    const auto it = ncomp.find(a.value("type", ""));
    if (it == ncomp.end())
      fail(path_, "accessor " + std::to_string(index) + " has unsupported type");
    comps = it->second;
    const int ct = a.value("componentType", 0);
    const int size = ct == 5126 || ct == 5125   ? 4
                     : ct == 5123 || ct == 5122 ? 2
                     : ct == 5121 || ct == 5120 ? 1
                                                : 0;
    if (size == 0)
      fail(path_, "accessor " + std::to_string(index) + " has unsupported componentType " +
                      std::to_string(ct));
    const size_t count = a.value("count", size_t{0});
    const json& view = at("bufferViews", a.value("bufferView", -1));
    const std::string& buf =
        buffers_.at(std::min<size_t>(view.value("buffer", 0), buffers_.size() - 1));
    const size_t stride = view.value("byteStride", size_t{0}) ? view.value("byteStride", size_t{0})
                                                              : size_t(size) * comps;
    const size_t start = view.value("byteOffset", size_t{0}) + a.value("byteOffset", size_t{0});
    const size_t view_end =
        view.value("byteOffset", size_t{0}) + view.value("byteLength", size_t{0});
    if (count > 0 &&
        (start + stride * (count - 1) + size_t(size) * comps > std::min(view_end, buf.size())))
      fail(path_, "accessor " + std::to_string(index) +
                      " reads past the end of its buffer (truncated file?)");
    const bool norm = a.value("normalized", false);
    std::vector<double> out(count * comps);
    for (size_t i = 0; i < count; ++i)
      for (int c = 0; c < comps; ++c) {
        const char* p = buf.data() + start + i * stride + size_t(c) * size;
        double v = 0;
        switch (ct) {
          case 5126: {
            float f;
            std::memcpy(&f, p, 4);
            v = f;
            break;
          }
          case 5125: {
            std::uint32_t u;
            std::memcpy(&u, p, 4);
            v = u;
            if (norm) v /= 4294967295.0;
            break;
          }
          case 5123: {
            std::uint16_t u;
            std::memcpy(&u, p, 2);
            v = u;
            if (norm) v /= 65535.0;
            break;
          }
          case 5122: {
            std::int16_t u;
            std::memcpy(&u, p, 2);
            v = u;
            if (norm) v = std::max(v / 32767.0, -1.0);
            break;
          }
          case 5121: {
            std::uint8_t u;
            std::memcpy(&u, p, 1);
            v = u;
            if (norm) v /= 255.0;
            break;
          }
          default: {
            std::int8_t u;
            std::memcpy(&u, p, 1);
            v = u;
            if (norm) v = std::max(v / 127.0, -1.0);
          }
        }
        out[i * comps + c] = v;
      }
    return out;
  }

  void add_mesh(TriMesh& m, int mesh_index, const Eigen::Matrix4d& world) {
    for (const auto& prim : at("meshes", mesh_index).value("primitives", json::array())) {
      if (prim.value("mode", 4) != 4)
        fail(path_, "primitive mode " + std::to_string(prim.value("mode", 4)) +
                        " is not supported (triangles only)");
      const json& attr = prim.value("attributes", json::object());
      if (!attr.contains("POSITION")) fail(path_, "a primitive has no POSITION attribute");
      int c = 0;
      const std::vector<double> pos = accessor(attr["POSITION"].get<int>(), c);
      if (c != 3) fail(path_, "POSITION must be VEC3");
      const size_t n = pos.size() / 3, base = m.vertices.size();
      std::vector<double> uv, col;
      int cu = 0, cc = 0;
      if (attr.contains("TEXCOORD_0")) uv = accessor(attr["TEXCOORD_0"].get<int>(), cu);
      if (attr.contains("COLOR_0")) col = accessor(attr["COLOR_0"].get<int>(), cc);
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
      if (prim.contains("indices")) {
        int ci = 0;
        idx = accessor(prim["indices"].get<int>(), ci);
      } else {
        for (size_t i = 0; i < n; ++i) idx.push_back(static_cast<double>(i));
      }
      if (idx.size() % 3)
        fail(path_, "index count " + std::to_string(idx.size()) + " is not a multiple of 3");
      for (size_t k = 0; k < idx.size(); k += 3) {
        std::array<int, 3> t;
        for (int q = 0; q < 3; ++q) {
          if (idx[k + q] >= n)
            fail(path_, "index " + std::to_string(static_cast<long>(idx[k + q])) +
                            " out of range (" + std::to_string(n) + " vertices)");
          t[q] = static_cast<int>(base + idx[k + q]);
        }
        m.triangles.push_back(t);
      }
      if (texture_image_ < 0 && prim.contains("material"))
        texture_image_ = base_color_image(prim["material"].get<int>());
    }
  }

  int base_color_image(int material) const {
    const json& mat = at("materials", material);
    const json pbr = mat.value("pbrMetallicRoughness", json::object());
    if (!pbr.contains("baseColorTexture")) return -1;
    const json& tex = at("textures", pbr["baseColorTexture"].value("index", -1));
    return tex.value("source", -1);
  }

  cv::Mat image(int index) const {
    const json& img = at("images", index);
    std::string bytes;
    if (img.contains("uri")) {
      bytes = uri_bytes(img["uri"].get<std::string>(), path_);
    } else {
      const json& view = at("bufferViews", img.value("bufferView", -1));
      const std::string& buf =
          buffers_.at(std::min<size_t>(view.value("buffer", 0), buffers_.size() - 1));
      const size_t off = view.value("byteOffset", size_t{0}),
                   len = view.value("byteLength", size_t{0});
      if (off + len > buf.size())
        fail(path_, "image " + std::to_string(index) + " lies past the end of its buffer");
      bytes = buf.substr(off, len);
    }
    cv::Mat out = cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, bytes.data()),
                               cv::IMREAD_COLOR);
    if (out.empty()) fail(path_, "image " + std::to_string(index) + " cannot be decoded");
    return out;
  }

  std::string path_;
  MeshReadOptions options_;
  json j_;
  std::vector<std::string> buffers_;
  bool any_uv_ = false, any_color_ = false;
  int texture_image_ = -1;
};

}  // namespace

TriMesh read_gltf(const std::string& path, const MeshReadOptions& options) {
  TriMesh m;
  try {
    m = Gltf(path, options).mesh();
  } catch (const nlohmann::json::exception& e) {
    fail(path, std::string("malformed glTF: ") + e.what());
  }
  if (m.triangles.empty()) fail(path, "no triangles in any mesh");
  validate_read(m, path);
  return m;
}

}  // namespace orthoface::mesh::io
