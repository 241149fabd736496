#include "sim/sim_folder.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "capture/camera_model.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"
#include "sim/truth_json.h"

namespace orthoface::sim {
namespace {

namespace fs = std::filesystem;

// The files of one write, each staged under a temporary name beside it (io::temp_path_for);
// commit() renames them all, the destructor removes whatever was not committed.
class Staging {
 public:
  explicit Staging(fs::path dir) : dir_(std::move(dir)) {}
  ~Staging() {
    std::error_code ec;
    for (const auto& [name, tmp] : files_) fs::remove(tmp, ec);
  }
  // Registers `name` and returns its temporary path, for writers that write files themselves.
  fs::path add(const std::string& name) {
    files_.emplace_back(name, io::temp_path_for((dir_ / name).string()));
    return files_.back().second;
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
    for (const auto& [name, tmp] : files_) {
      std::error_code ec;
      fs::rename(tmp, dir_ / name, ec);
      if (ec)
        throw std::runtime_error("cannot write " + (dir_ / name).string() + ": " + ec.message());
    }
    files_.clear();
  }

 private:
  fs::path dir_;
  std::vector<std::pair<std::string, fs::path>> files_;  // name, its temporary
};

// Stages truth.obj (+ truth.mtl, truth.png) written by mesh::write_mesh into a scratch folder.
void stage_mesh(Staging& st, const fs::path& dir, const mesh::TriMesh& mesh) {
  const fs::path scratch = io::temp_path_for((dir / "truth_mesh").string());
  std::error_code ec;
  if (!fs::create_directory(scratch, ec))
    throw std::runtime_error("cannot write " + (dir / "truth.obj").string() + ": " + ec.message());
  try {
    mesh::write_mesh(mesh, (scratch / "truth.obj").string());
    for (const auto& e : fs::directory_iterator(scratch))
      fs::rename(e.path(), st.add(e.path().filename().string()));
  } catch (...) {
    fs::remove_all(scratch, ec);
    throw;
  }
  fs::remove_all(scratch, ec);
}

}  // namespace

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
  stage_mesh(st, dir, head.mesh);
  // These writers do their own tmp + rename, onto our staged names.
  write_truth_json(make_truth(capture, options, head.name, "truth.obj"),
                   st.add("landmarks.json").string());
  capture::write_rig(capture.nominal_rig, st.add("rig.yaml").string());
  st.commit();
}

}  // namespace orthoface::sim
