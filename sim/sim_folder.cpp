#include "sim/sim_folder.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "sim/truth_json.h"

namespace orthoface::sim {
namespace {

namespace fs = std::filesystem;

// The files of one write, staged as name.tmp; commit() renames them all, the destructor removes
// whatever was not committed.
class Staging {
 public:
  explicit Staging(fs::path dir) : dir_(std::move(dir)) {}
  ~Staging() {
    std::error_code ec;
    for (const auto& name : names_) fs::remove(tmp(name), ec);
  }
  fs::path tmp(const std::string& name) const { return dir_ / (name + ".tmp"); }
  // Registers `name` and returns its tmp path, for writers that write files themselves.
  fs::path add(const std::string& name) {
    names_.push_back(name);
    return tmp(name);
  }
  void text(const std::string& name, const std::string& content) {
    std::ofstream f(add(name), std::ios::binary);
    f << content;
    if (!f) throw std::runtime_error("cannot write " + (dir_ / name).string());
  }
  void png(const std::string& name, const cv::Mat& image) {
    std::vector<uchar> bytes;
    if (image.empty() || !cv::imencode(".png", image, bytes))
      throw std::runtime_error("cannot encode " + (dir_ / name).string() + " as PNG");
    std::ofstream f(add(name), std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!f) throw std::runtime_error("cannot write " + (dir_ / name).string());
  }
  void commit() {
    for (const auto& name : names_) {
      std::error_code ec;
      fs::rename(tmp(name), dir_ / name, ec);
      if (ec) throw std::runtime_error("cannot write " + (dir_ / name).string() + ": " + ec.message());
    }
    names_.clear();
  }

 private:
  fs::path dir_;
  std::vector<std::string> names_;
};

std::string obj_text(const model::TriMesh& mesh, const std::string& mtl_name, bool textured) {
  std::string s = "# orthoface mesh: head frame, millimetres (+x subject's left, +y up, +z out of the face)\n";
  if (textured) s += "mtllib " + mtl_name + "\nusemtl skin\n";
  char buf[160];
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d& v = mesh.vertices[i];
    if (mesh.colors.empty())
      std::snprintf(buf, sizeof buf, "v %.6f %.6f %.6f\n", v.x(), v.y(), v.z());
    else
      std::snprintf(buf, sizeof buf, "v %.6f %.6f %.6f %.4f %.4f %.4f\n", v.x(), v.y(), v.z(),
                    mesh.colors[i].x(), mesh.colors[i].y(), mesh.colors[i].z());
    s += buf;
  }
  if (textured)
    for (const auto& uv : mesh.uvs) {
      std::snprintf(buf, sizeof buf, "vt %.6f %.6f\n", uv.x(), uv.y());
      s += buf;
    }
  for (const auto& t : mesh.triangles) {
    if (textured)
      std::snprintf(buf, sizeof buf, "f %d/%d %d/%d %d/%d\n", t[0] + 1, t[0] + 1, t[1] + 1,
                    t[1] + 1, t[2] + 1, t[2] + 1);
    else
      std::snprintf(buf, sizeof buf, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    s += buf;
  }
  return s;
}

std::string mtl_text(const std::string& texture_name) {
  return "newmtl skin\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " + texture_name + "\n";
}

// Stages name.obj (+ name.mtl, name_texture.png).
void stage_obj(Staging& st, const model::TriMesh& mesh, const std::string& stem) {
  const bool textured = !mesh.texture.empty() && mesh.uvs.size() == mesh.vertices.size();
  st.text(stem + ".obj", obj_text(mesh, stem + ".mtl", textured));
  if (!textured) return;
  st.text(stem + ".mtl", mtl_text(stem + "_texture.png"));
  st.png(stem + "_texture.png", mesh.texture);
}

}  // namespace

void write_obj(const model::TriMesh& mesh, const std::string& obj_path) {
  model::check_mesh(mesh, "write_obj " + obj_path);
  const fs::path p(obj_path);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  if (!fs::is_directory(dir)) throw std::runtime_error("cannot write " + obj_path + ": no such folder");
  Staging st(dir);
  stage_obj(st, mesh, p.stem().string());
  st.commit();
}

void write_simulation(const std::string& dir, const Head& head, const Capture& capture,
                      const RigOptions& options) {
  if (!fs::is_directory(dir)) throw std::runtime_error("output folder " + dir + ": not a folder");
  Staging st(dir);
  st.png("front.png", capture.front);
  st.png("side.png", capture.side);
  st.png("front_mask.png", capture.front_mask);
  st.png("side_mask.png", capture.side_mask);
  st.png("background.png", capture.background_front);
  st.png("background_side.png", capture.background_side);
  stage_obj(st, head.mesh, "truth");
  // These writers do their own tmp + rename, onto our staged names.
  write_truth_json(make_truth(capture, options, head.name, "truth.obj"),
                   st.add("landmarks.json").string());
  capture::write_rig(capture.nominal_rig, st.add("rig.yaml").string());
  st.commit();
}

}  // namespace orthoface::sim
