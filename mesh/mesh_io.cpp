// Mesh reading / writing. The parsers are written by hand rather than with OpenMesh::IO:
// OpenMesh's readers only return a bool (no reason to name in the error), print to omerr and
// skip faces with bad indices instead of failing, and its halfedge mesh refuses non-manifold
// faces, which we must load so that topology checks can report them. OBJ texture coordinates
// also come back per halfedge there, so the UV-seam split would have to be redone anyway.
#include "mesh/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "io/image_file.h"
#include "mesh/mesh_io_detail.h"

namespace orthoface::mesh {

namespace io {

void fail(const std::string& path, const std::string& message) {
  throw std::runtime_error(path + ": " + message);
}

std::string read_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "file does not exist");
  if (std::filesystem::is_directory(path, ec)) fail(path, "is a directory, not a mesh file");
  // A device or pipe (e.g. /dev/zero named by a material or buffer) could be read forever.
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "is not a regular file");
  constexpr std::uintmax_t kMaxBytes = std::uintmax_t(1) << 30;
  if (std::filesystem::file_size(path, ec) > kMaxBytes) fail(path, "is larger than 1 GiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

cv::Mat load_texture(const std::string& image_path, const std::string& mesh_path) {
  std::filesystem::path p(image_path);
  if (p.is_relative()) p = std::filesystem::path(mesh_path).parent_path() / p;
  if (!std::filesystem::exists(p))
    fail(mesh_path, "texture image " + p.string() + " does not exist");
  cv::Mat img = orthoface::io::imread_accepted(p.string(), cv::IMREAD_COLOR);
  if (img.empty()) fail(mesh_path, "texture image " + p.string() + " cannot be decoded");
  return img;
}

void validate_read(const TriMesh& mesh, const std::string& path) {
  if (mesh.vertices.empty()) fail(path, "no vertices");
  if (mesh.triangles.empty())
    fail(path, "no faces (" + std::to_string(mesh.vertices.size()) + " vertices only)");
  try {
    check_mesh(mesh, path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  for (size_t i = 0; i < mesh.uvs.size(); ++i)
    if (!mesh.uvs[i].allFinite())
      fail(path, "texture coordinate " + std::to_string(i) + " is not finite");
  for (const auto& t : mesh.triangles)
    if ((mesh.vertices[t[1]] - mesh.vertices[t[0]])
            .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
            .norm() > 0)
      return;
  fail(path, "all " + std::to_string(mesh.triangles.size()) + " triangles have zero area");
}

namespace {

// Parses a double; rejects trailing garbage. NaN / inf parse and are caught by validate_read.
bool parse_double(const std::string& s, double& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size();
}

std::string at_line(size_t line) { return "line " + std::to_string(line) + ": "; }

// OBJ index (1-based, negative = relative to the end) to 0-based; throws when out of range.
int obj_index(const std::string& tok, int count, const std::string& path, size_t line,
              const char* what) {
  char* end = nullptr;
  const long v = std::strtol(tok.c_str(), &end, 10);
  if (tok.empty() || end != tok.c_str() + tok.size() || v == 0)
    fail(path, at_line(line) + "bad " + what + " index '" + tok + "'");
  const long i = v > 0 ? v - 1 : count + v;
  if (i < 0 || i >= count)
    fail(path, at_line(line) + what + " index " + tok + " out of range (" + std::to_string(count) +
                   " defined so far)");
  return static_cast<int>(i);
}

// map_Kd of the first material in an MTL file, or "" (options, e.g. "-s 1 1 1", are skipped).
std::string mtl_texture(const std::string& mtl_path, const std::string& obj_path) {
  std::ifstream in(mtl_path);
  if (!in) fail(obj_path, "material library " + mtl_path + " does not exist");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key != "map_Kd") continue;
    std::string tok, last;
    while (ls >> tok) last = tok;
    return last;
  }
  return "";
}

// One face corner: position index and texture index (-1 = none).
using Corner = std::pair<int, int>;

// Output vertices keep the OBJ position order; a position used with a second texture
// coordinate (a UV seam) is duplicated at the end.
TriMesh assemble_obj(const std::vector<Eigen::Vector3d>& pos,
                     const std::vector<Eigen::Vector3d>& col,
                     const std::vector<Eigen::Vector2d>& tex,
                     const std::vector<std::vector<Corner>>& faces) {
  TriMesh m;
  m.vertices = pos;
  m.uvs.assign(pos.size(), Eigen::Vector2d(0, 0));
  m.colors = col.size() == pos.size()
                 ? col
                 : std::vector<Eigen::Vector3d>(pos.size(), Eigen::Vector3d(1, 1, 1));
  std::vector<int> first_uv(pos.size(), -2);
  std::map<Corner, int> extra;
  for (const auto& f : faces) {
    std::vector<int> poly;
    for (const auto& [vi, ti] : f) {
      if (first_uv[vi] == -2) {
        first_uv[vi] = ti;
        if (ti >= 0) m.uvs[vi] = tex[ti];
      }
      if (first_uv[vi] == ti) {
        poly.push_back(vi);
        continue;
      }
      const auto [it, added] = extra.try_emplace({vi, ti}, static_cast<int>(m.vertices.size()));
      if (added) {
        m.vertices.push_back(pos[vi]);
        m.uvs.push_back(ti >= 0 ? tex[ti] : Eigen::Vector2d(0, 0));
        m.colors.push_back(m.colors[vi]);
      }
      poly.push_back(it->second);
    }
    for (size_t k = 1; k + 1 < poly.size(); ++k)
      m.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  }
  if (col.size() != pos.size()) m.colors.clear();
  return m;
}

}  // namespace

TriMesh read_obj(const std::string& path, const MeshReadOptions& options) {
  std::istringstream in(read_bytes(path));
  std::vector<Eigen::Vector3d> pos, col;
  std::vector<Eigen::Vector2d> tex;
  std::vector<std::vector<Corner>> faces;
  bool any_uv = false;
  std::string line, mtllib;
  size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream ls(line);
    std::string key;
    if (!(ls >> key) || key[0] == '#') continue;
    std::vector<std::string> tok;
    for (std::string t; ls >> t;) tok.push_back(t);
    if (key == "v" || key == "vt") {
      const size_t need = key == "v" ? 3 : 2;
      double val[6] = {0, 0, 0, 0, 0, 0};
      if (tok.size() < need)
        fail(path, at_line(line_no) + key + " needs " + std::to_string(need) + " numbers");
      for (size_t k = 0; k < std::min<size_t>(tok.size(), 6); ++k)
        if (!parse_double(tok[k], val[k]))
          fail(path, at_line(line_no) + "'" + tok[k] + "' is not a number");
      for (size_t k = 0; k < need; ++k)
        if (!std::isfinite(val[k])) fail(path, at_line(line_no) + key + " has a non-finite value");
      if (key == "vt") {
        tex.emplace_back(val[0], val[1]);
      } else {
        pos.emplace_back(val[0], val[1], val[2]);
        if (tok.size() >= 6) col.emplace_back(val[3], val[4], val[5]);
      }
    } else if (key == "f") {
      if (tok.size() < 3) fail(path, at_line(line_no) + "face with fewer than 3 vertices");
      faces.emplace_back();
      for (const auto& t : tok) {
        const size_t s1 = t.find('/');
        const int vi =
            obj_index(t.substr(0, s1), static_cast<int>(pos.size()), path, line_no, "vertex");
        int ti = -1;
        if (s1 != std::string::npos) {
          const size_t s2 = t.find('/', s1 + 1);
          const std::string ts =
              t.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
          if (!ts.empty())
            ti = obj_index(ts, static_cast<int>(tex.size()), path, line_no, "texture");
        }
        any_uv |= ti >= 0;
        faces.back().push_back({vi, ti});
      }
    } else if (key == "mtllib" && !tok.empty()) {
      mtllib = line.substr(line.find(tok[0]));  // names may contain spaces
      while (!mtllib.empty() && std::isspace(static_cast<unsigned char>(mtllib.back())))
        mtllib.pop_back();
    }
  }
  if (pos.empty() && faces.empty()) fail(path, "empty mesh (no vertices, no faces)");
  if (faces.empty()) fail(path, "no faces (" + std::to_string(pos.size()) + " vertices only)");
  TriMesh m = assemble_obj(pos, col, tex, faces);
  if (!any_uv) m.uvs.clear();
  if (options.load_texture) {
    if (!options.texture_path.empty()) {
      m.texture = load_texture(options.texture_path, path);
    } else if (!mtllib.empty() && any_uv) {
      const auto mtl = std::filesystem::path(path).parent_path() / mtllib;
      const std::string image = mtl_texture(mtl.string(), path);
      // The image is named relative to the MTL, the MTL relative to the mesh: load_texture takes
      // a path relative to the mesh's folder.
      if (!image.empty())
        m.texture =
            load_texture((std::filesystem::path(mtllib).parent_path() / image).string(), path);
    }
  }
  validate_read(m, path);
  return m;
}

}  // namespace io

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace

TriMesh read_mesh(const std::string& path, const MeshReadOptions& options) {
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return io::read_obj(path, options);
  if (ext == ".ply") return io::read_ply(path, options);
  if (ext == ".off" || ext == ".coff") return io::read_off(path);
  if (ext == ".glb" || ext == ".gltf") return io::read_gltf(path, options);
  io::fail(path, "unknown mesh format '" + ext + "' (expected .obj, .ply, .off, .glb or .gltf)");
}

void write_mesh(const TriMesh& mesh, const std::string& path, const MeshWriteOptions& options) {
  check_mesh(mesh, "write_mesh " + path);
  const std::string ext = lower_extension(path);
  if (ext != ".obj" && ext != ".ply" && ext != ".off")
    io::fail(path, "cannot write mesh format '" + ext + "' (expected .obj, .ply or .off)");
  orthoface::io::FileGroup files;  // the mesh with its .mtl and texture, or none of them
  if (ext == ".obj") io::write_obj(mesh, path);
  if (ext == ".ply") io::write_ply(mesh, path, options.binary);
  if (ext == ".off") io::write_off(mesh, path);
  files.commit();
}

}  // namespace orthoface::mesh
