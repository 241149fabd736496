// PLY reading (ascii, binary little / big endian) and writing.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "mesh/mesh_io_detail.h"

namespace orthoface::mesh::io {

namespace {

enum class Format { Ascii, BinaryLE, BinaryBE };

struct Property {
  std::string name, type, list_count_type;  // list_count_type empty: scalar
};

struct Element {
  std::string name;
  size_t count = 0;
  std::vector<Property> props;
};

int type_size(const std::string& t) {
  static const std::map<std::string, int> sizes = {
      {"char", 1},  {"uchar", 1},   {"int8", 1},   {"uint8", 1},  {"short", 2}, {"ushort", 2},
      {"int16", 2}, {"uint16", 2},  {"int", 4},    {"uint", 4},   {"int32", 4}, {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(t);
  return it == sizes.end() ? 0 : it->second;
}

// Reads values from the data section in the file's format.
class Reader {
 public:
  Reader(const std::string& data, size_t pos, Format f, const std::string& path)
      : data_(data), pos_(pos), format_(f), path_(path) {}

  double value(const std::string& type, const std::string& where) {
    if (format_ == Format::Ascii) return ascii(where);
    const int n = type_size(type);
    if (pos_ + n > data_.size()) fail(path_, "truncated binary data at " + where);
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if ((format_ == Format::BinaryBE) == (std::endian::native == std::endian::little))
      std::reverse(b, b + n);
    auto get = [&](auto v) {
      std::memcpy(&v, b, sizeof(v));
      return static_cast<double>(v);
    };
    if (type == "char" || type == "int8") return get(std::int8_t{});
    if (type == "uchar" || type == "uint8") return get(std::uint8_t{});
    if (type == "short" || type == "int16") return get(std::int16_t{});
    if (type == "ushort" || type == "uint16") return get(std::uint16_t{});
    if (type == "int" || type == "int32") return get(std::int32_t{});
    if (type == "uint" || type == "uint32") return get(std::uint32_t{});
    if (type == "float" || type == "float32") return get(float{});
    return get(double{});
  }
  size_t remaining() const { return data_.size() - pos_; }

 private:
  double ascii(const std::string& where) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ >= data_.size()) fail(path_, "truncated ascii data at " + where);
    size_t end = pos_;
    while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
    const std::string tok = data_.substr(pos_, end - pos_);
    pos_ = end;
    char* e = nullptr;
    const double v = std::strtod(tok.c_str(), &e);
    if (e != tok.c_str() + tok.size()) fail(path_, "'" + tok + "' is not a number at " + where);
    return v;
  }

  const std::string& data_;
  size_t pos_;
  Format format_;
  const std::string& path_;
};

// Parses the header; returns the offset of the data section.
size_t parse_header(const std::string& d, const std::string& path, Format& format,
                    std::vector<Element>& elements, std::string& texture_file) {
  if (d.compare(0, 3, "ply") != 0) fail(path, "not a PLY file (no 'ply' magic)");
  const size_t end = d.find("end_header");
  if (end == std::string::npos) fail(path, "PLY header has no end_header");
  size_t data = d.find('\n', end);
  if (data == std::string::npos) fail(path, "PLY header not terminated by a newline");
  std::istringstream hs(d.substr(0, end));
  std::string line;
  bool have_format = false;
  while (std::getline(hs, line)) {
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "format") {
      std::string f;
      ls >> f;
      have_format = true;
      if (f == "ascii")
        format = Format::Ascii;
      else if (f == "binary_little_endian")
        format = Format::BinaryLE;
      else if (f == "binary_big_endian")
        format = Format::BinaryBE;
      else
        fail(path, "unknown PLY format '" + f + "'");
    } else if (key == "element") {
      Element e;
      double count = -1;
      ls >> e.name >> count;
      if (!ls || count < 0 || count > 2e9) fail(path, "bad PLY element line '" + line + "'");
      e.count = static_cast<size_t>(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) fail(path, "PLY property before any element");
      Property p;
      std::string t;
      ls >> t;
      if (t == "list")
        ls >> p.list_count_type >> p.type >> p.name;
      else {
        p.type = t;
        ls >> p.name;
      }
      if (!ls || type_size(p.type) == 0 ||
          (!p.list_count_type.empty() && type_size(p.list_count_type) == 0))
        fail(path, "bad PLY property line '" + line + "'");
      elements.back().props.push_back(p);
    } else if (key == "comment") {
      std::string word;
      ls >> word;
      if (word == "TextureFile") std::getline(ls >> std::ws, texture_file);
    }
  }
  if (!have_format) fail(path, "PLY header has no format line");
  return data + 1;
}

// Smallest number of bytes one element can take; used to reject absurd counts before allocating.
size_t min_bytes(const Element& e, Format f) {
  size_t n = 0;
  for (const auto& p : e.props)
    n += f == Format::Ascii ? 2 : type_size(p.list_count_type.empty() ? p.type : p.list_count_type);
  return std::max<size_t>(n, 1);
}

int scalar_role(const std::string& n) {  // 0..2 xyz, 3..5 rgb, 6..7 uv, -1 other
  static const std::map<std::string, int> roles = {{"x", 0},
                                                   {"y", 1},
                                                   {"z", 2},
                                                   {"red", 3},
                                                   {"green", 4},
                                                   {"blue", 5},
                                                   {"r", 3},
                                                   {"g", 4},
                                                   {"b", 5},
                                                   {"diffuse_red", 3},
                                                   {"diffuse_green", 4},
                                                   {"diffuse_blue", 5},
                                                   {"s", 6},
                                                   {"t", 7},
                                                   {"u", 6},
                                                   {"v", 7},
                                                   {"texture_u", 6},
                                                   {"texture_v", 7},
                                                   {"texture_s", 6},
                                                   {"texture_t", 7}};
  const auto it = roles.find(n);
  return it == roles.end() ? -1 : it->second;
}

}  // namespace

TriMesh read_ply(const std::string& path, const MeshReadOptions& options) {
  const std::string d = read_bytes(path);
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::string texture_file;
  const size_t data_start = parse_header(d, path, format, elements, texture_file);
  Reader r(d, data_start, format, path);
  TriMesh m;
  std::vector<std::vector<int>> faces;
  std::vector<std::vector<Eigen::Vector2d>> wedge_uvs;  // MeshLab "texcoord" per face corner
  bool have_vertex = false, have_color = false, have_uv = false;
  for (const Element& e : elements) {
    if (e.count > r.remaining() / min_bytes(e, format))
      fail(path, "element '" + e.name + "' claims " + std::to_string(e.count) +
                     " entries but only " + std::to_string(r.remaining()) +
                     " bytes of data remain (corrupt or truncated)");
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    have_vertex |= is_vertex;
    for (size_t i = 0; i < e.count; ++i) {
      double v[8] = {0, 0, 0, 1, 1, 1, 0, 0};
      std::vector<int> poly;
      std::vector<Eigen::Vector2d> poly_uv;
      for (const Property& p : e.props) {
        const std::string where = e.name + " " + std::to_string(i) + " (" + p.name + ")";
        if (p.list_count_type.empty()) {
          const double x = r.value(p.type, where);
          const int role = is_vertex ? scalar_role(p.name) : -1;
          if (role >= 0)
            v[role] = (role >= 3 && role <= 5 && type_size(p.type) == 1) ? x / 255.0 : x;
          if (is_vertex && role >= 3 && role <= 5) have_color = true;
          if (is_vertex && role >= 6) have_uv = true;
          continue;
        }
        const double n = r.value(p.list_count_type, where);
        if (n < 0 || n > 1e6 || n != std::floor(n)) fail(path, "bad list length at " + where);
        std::vector<double> vals(static_cast<size_t>(n));
        for (double& x : vals) x = r.value(p.type, where);
        if (is_face && (p.name == "vertex_indices" || p.name == "vertex_index")) {
          for (double x : vals) poly.push_back(static_cast<int>(std::clamp(x, -1.0, 2e9)));
        } else if (is_face && p.name == "texcoord") {
          for (size_t k = 0; k + 1 < vals.size(); k += 2)
            poly_uv.emplace_back(vals[k], vals[k + 1]);
        }
      }
      if (is_face) {
        faces.push_back(poly);
        wedge_uvs.push_back(poly_uv);
      }
      if (is_vertex) {
        m.vertices.emplace_back(v[0], v[1], v[2]);
        m.colors.emplace_back(v[3], v[4], v[5]);
        m.uvs.emplace_back(v[6], v[7]);
      }
    }
  }
  if (!have_vertex) fail(path, "PLY file has no vertex element");
  const int nv = static_cast<int>(m.vertices.size());
  bool wedges = false;
  for (const auto& w : wedge_uvs) wedges |= !w.empty() && !have_uv;
  std::map<std::pair<int, std::pair<double, double>>, int> split;  // (vertex, uv) -> new vertex
  TriMesh out = wedges ? TriMesh{} : m;
  out.triangles.clear();
  for (size_t f = 0; f < faces.size(); ++f) {
    std::vector<int> poly;
    for (size_t k = 0; k < faces[f].size(); ++k) {
      const int idx = faces[f][k];
      if (idx < 0 || idx >= nv)
        fail(path, "face " + std::to_string(f) + ": vertex index " + std::to_string(idx) +
                       " out of range [0, " + std::to_string(nv) + ")");
      if (!wedges) {
        poly.push_back(idx);
        continue;
      }
      const Eigen::Vector2d uv =
          f < wedge_uvs.size() && k < wedge_uvs[f].size() ? wedge_uvs[f][k] : Eigen::Vector2d(0, 0);
      const auto [it, added] =
          split.try_emplace({idx, {uv.x(), uv.y()}}, static_cast<int>(out.vertices.size()));
      if (added) {
        out.vertices.push_back(m.vertices[idx]);
        out.colors.push_back(m.colors[idx]);
        out.uvs.push_back(uv);
      }
      poly.push_back(it->second);
    }
    if (poly.size() < 3) fail(path, "face " + std::to_string(f) + " has fewer than 3 vertices");
    for (size_t k = 1; k + 1 < poly.size(); ++k)
      out.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  }
  if (!have_color) out.colors.clear();
  if (!have_uv && !wedges) out.uvs.clear();
  if (options.load_texture && !out.uvs.empty()) {
    if (!options.texture_path.empty())
      out.texture = load_texture(options.texture_path, path);
    else if (!texture_file.empty())
      out.texture = load_texture(texture_file, path);
  }
  validate_read(out, path);
  return out;
}

void write_ply(const TriMesh& mesh, const std::string& path, bool binary) {
  const std::filesystem::path p(path);
  const bool textured = !mesh.texture.empty() && !mesh.uvs.empty();
  const std::string stem = p.stem().string();
  if (textured)
    orthoface::io::write_image_atomically((p.parent_path() / (stem + ".png")).string(),
                                          mesh.texture);
  orthoface::io::write_stream_atomically(path, [&](std::ostream& out) {
    const bool colors = !mesh.colors.empty(), uvs = !mesh.uvs.empty();
    out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
        << "comment orthoface mesh\n";
    if (textured) out << "comment TextureFile " << stem << ".png\n";
    out << "element vertex " << mesh.vertices.size()
        << "\nproperty float x\nproperty float y\nproperty float z\n";
    if (colors) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (uvs) out << "property float s\nproperty float t\n";
    out << "element face " << mesh.triangles.size()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](auto v) {
      if (binary) {
        if constexpr (std::endian::native == std::endian::big) {
          unsigned char b[sizeof(v)];
          std::memcpy(b, &v, sizeof(v));
          std::reverse(b, b + sizeof(v));
          out.write(reinterpret_cast<const char*>(b), sizeof(v));
        } else {
          out.write(reinterpret_cast<const char*>(&v), sizeof(v));
        }
      } else {
        out << +v << ' ';
      }
    };
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      for (int k = 0; k < 3; ++k) put(static_cast<float>(mesh.vertices[i][k]));
      if (colors)
        for (int k = 0; k < 3; ++k)
          put(static_cast<std::uint8_t>(
              std::lround(std::clamp(mesh.colors[i][k], 0.0, 1.0) * 255)));
      if (uvs)
        for (int k = 0; k < 2; ++k) put(static_cast<float>(mesh.uvs[i][k]));
      if (!binary) out << '\n';
    }
    for (const auto& t : mesh.triangles) {
      put(static_cast<std::uint8_t>(3));
      for (int k = 0; k < 3; ++k) put(static_cast<std::int32_t>(t[k]));
      if (!binary) out << '\n';
    }
  });
}

}  // namespace orthoface::mesh::io
