// OFF reading, OBJ (+ MTL + PNG) and OFF writing.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "mesh/mesh_io_detail.h"

namespace orthoface::mesh::io {

namespace {

// Next non-empty, non-comment line split into tokens; false at the end of the input.
bool next_tokens(std::istringstream& in, std::vector<std::string>& tok, size_t& line_no) {
  std::string line;
  while (std::getline(in, line)) {
    ++line_no;
    if (const size_t c = line.find('#'); c != std::string::npos) line.resize(c);
    std::istringstream ls(line);
    tok.clear();
    for (std::string t; ls >> t;) tok.push_back(t);
    if (!tok.empty()) return true;
  }
  return false;
}

double number(const std::string& s, const std::string& path, size_t line_no) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size())
    fail(path, "line " + std::to_string(line_no) + ": '" + s + "' is not a number");
  return v;
}

}  // namespace

TriMesh read_off(const std::string& path) {
  std::istringstream in(read_bytes(path));
  std::vector<std::string> tok;
  size_t line_no = 0;
  if (!next_tokens(in, tok, line_no)) fail(path, "empty file");
  const std::string head = tok[0];
  if (head != "OFF" && head != "COFF") fail(path, "not an OFF file (first word '" + head + "')");
  tok.erase(tok.begin());
  if (tok.empty() && !next_tokens(in, tok, line_no)) fail(path, "missing vertex / face counts");
  if (tok.size() < 2)
    fail(path, "line " + std::to_string(line_no) + ": expected vertex and face counts");
  const double nv = number(tok[0], path, line_no), nf = number(tok[1], path, line_no);
  if (nv < 0 || nf < 0 || nv > 1e8 || nf > 1e8 || nv != std::floor(nv) || nf != std::floor(nf))
    fail(path, "bad vertex / face counts " + tok[0] + " " + tok[1]);
  TriMesh m;
  bool colors = head == "COFF";
  for (int i = 0; i < static_cast<int>(nv); ++i) {
    if (!next_tokens(in, tok, line_no))
      fail(path, "truncated: " + std::to_string(i) + " of " + std::to_string(long(nv)) +
                     " vertices");  // not tok[0]: a failed read leaves tok empty
    if (tok.size() < 3) fail(path, "line " + std::to_string(line_no) + ": vertex needs x y z");
    m.vertices.emplace_back(number(tok[0], path, line_no), number(tok[1], path, line_no),
                            number(tok[2], path, line_no));
    if (colors && tok.size() >= 6) {
      Eigen::Vector3d c(number(tok[3], path, line_no), number(tok[4], path, line_no),
                        number(tok[5], path, line_no));
      m.colors.push_back(c.maxCoeff() > 1 ? c / 255.0 : c);
    } else {
      colors = false;
    }
  }
  for (int f = 0; f < static_cast<int>(nf); ++f) {
    if (!next_tokens(in, tok, line_no))
      fail(path, "truncated: " + std::to_string(f) + " faces read");
    const double n = number(tok[0], path, line_no);
    // Compared as doubles first: a count beyond size_t would make the cast undefined.
    if (!(n >= 3 && n <= double(tok.size() - 1)) || n != std::floor(n))
      fail(path, "line " + std::to_string(line_no) + ": bad face");
    std::vector<int> poly;
    for (int k = 1; k <= static_cast<int>(n); ++k) {
      const double idx = number(tok[k], path, line_no);
      if (idx < 0 || idx >= nv || idx != std::floor(idx))
        fail(path, "line " + std::to_string(line_no) + ": vertex index " + tok[k] +
                       " out of range [0, " + std::to_string(static_cast<long>(nv)) + ")");
      poly.push_back(static_cast<int>(idx));
    }
    for (size_t k = 1; k + 1 < poly.size(); ++k)
      m.triangles.push_back({poly[0], poly[k], poly[k + 1]});
  }
  if (!colors) m.colors.clear();
  validate_read(m, path);
  return m;
}

void write_obj(const TriMesh& mesh, const std::string& path) {
  const std::filesystem::path p(path);
  const std::string stem = p.stem().string();
  const bool textured = !mesh.texture.empty() && !mesh.uvs.empty();
  if (textured) {
    orthoface::io::write_image_atomically((p.parent_path() / (stem + ".png")).string(),
                                          mesh.texture);
    orthoface::io::write_text_atomically(
        (p.parent_path() / (stem + ".mtl")).string(),
        "newmtl skin\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " + stem + ".png\n");
  }
  orthoface::io::write_stream_atomically(path, [&](std::ostream& out) {
    char buf[160];
    out << "# orthoface mesh: " << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
        << " triangles\n";
    if (textured) out << "mtllib " << stem << ".mtl\nusemtl skin\n";
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      const auto& v = mesh.vertices[i];
      if (mesh.colors.empty()) {
        std::snprintf(buf, sizeof(buf), "v %.9g %.9g %.9g\n", v.x(), v.y(), v.z());
      } else {
        const auto& c = mesh.colors[i];
        std::snprintf(buf, sizeof(buf), "v %.9g %.9g %.9g %.6g %.6g %.6g\n", v.x(), v.y(), v.z(),
                      c.x(), c.y(), c.z());
      }
      out << buf;
    }
    for (const auto& uv : mesh.uvs) {
      std::snprintf(buf, sizeof(buf), "vt %.9g %.9g\n", uv.x(), uv.y());
      out << buf;
    }
    const bool with_uv = !mesh.uvs.empty();
    for (const auto& t : mesh.triangles) {
      out << 'f';
      for (int k = 0; k < 3; ++k) {
        out << ' ' << t[k] + 1;
        if (with_uv) out << '/' << t[k] + 1;
      }
      out << '\n';
    }
  });
}

void write_off(const TriMesh& mesh, const std::string& path) {
  orthoface::io::write_stream_atomically(path, [&](std::ostream& out) {
    const bool colors = !mesh.colors.empty();
    out << (colors ? "COFF\n" : "OFF\n") << mesh.vertices.size() << ' ' << mesh.triangles.size()
        << " 0\n";
    char buf[160];
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      const auto& v = mesh.vertices[i];
      std::snprintf(buf, sizeof(buf), "%.9g %.9g %.9g", v.x(), v.y(), v.z());
      out << buf;
      if (colors) {
        const Eigen::Vector3d c = (mesh.colors[i].cwiseMax(0).cwiseMin(1) * 255).array().round();
        out << ' ' << static_cast<int>(c.x()) << ' ' << static_cast<int>(c.y()) << ' '
            << static_cast<int>(c.z()) << " 255";
      }
      out << '\n';
    }
    for (const auto& t : mesh.triangles) out << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
  });
}

}  // namespace orthoface::mesh::io
