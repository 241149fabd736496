// orthoface eval: compare a reconstruction folder with a ground truth (seed 002 §4.1).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "app/cli.h"
#include "app/commands.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"
#include "model/evaluate.h"
#include "reconstruct/reconstruction.h"
#include "render/renderer.h"
#include "sim/truth_json.h"

namespace orthoface::app {
namespace {

namespace fs = std::filesystem;
using Landmarks = std::map<std::string, Eigen::Vector3d>;

Command eval_command() {
  return {"eval",
          "Compare a reconstruction folder with the truth: relative error (mean surface distance "
          "on the face region / true bounding-box diagonal, seed 002 §4.1), landmark errors in "
          "mm. Writes DIR/eval.json, DIR/error.ply (error colours: blue inside, green 0, red "
          "outside) and DIR/error.png (rendered from the front and at 60 degrees).",
          "orthoface eval DIR --truth SIMDIR|MESH [--range MM]",
          {{"truth", true, "SIMDIR|MESH  folder from `orthoface simulate` or a mesh file"},
           {"range", true, "MM  error that saturates the colours (default 3)"}},
          1};
}

cv::Mat error_picture(const mesh::TriMesh& colored, const capture::CameraModel& front) {
  render::Renderer renderer;
  render::RenderOptions o;
  o.background = cv::Scalar(255, 255, 255);
  o.light.ambient = 0.7, o.light.diffuse = 0.4;
  const double distance = front.projection == capture::Projection::Perspective
                              ? front.cam_from_head.translation().norm()
                              : 1000.0;
  cv::Mat a = renderer.render(colored, capture::camera_at(front, 0, 0, distance), o).image;
  cv::Mat b = renderer.render(colored, capture::camera_at(front, -M_PI / 3, 0, distance), o).image;
  cv::Mat both;
  cv::hconcat(a, b, both);
  return both;
}

}  // namespace

int run_eval(int argc, char** argv) {
  const Command command = eval_command();
  const Args args = parse_args(command, argc, argv);
  if (args.help) {
    print_help(command);
    return 0;
  }
  if (args.positional.size() != 1)
    throw std::invalid_argument("eval: give the reconstruction folder DIR");
  if (!args.has("truth")) throw std::invalid_argument("eval: --truth SIMDIR|MESH is required");
  const double range = args.has("range") ? to_double("range", args.get("range"), 0.01, 1000) : 3.0;
  const fs::path dir = args.positional[0];
  const reconstruct::Reconstruction folder = reconstruct::read_reconstruction(dir.string());
  if (folder.landmarks.empty())
    throw std::runtime_error("reconstruction folder " + dir.string() + ": no landmarks.json");
  const mesh::TriMesh& rec = folder.mesh;
  const Landmarks& rec_landmarks = folder.landmarks;
  const fs::path truth_path = args.get("truth");
  mesh::TriMesh truth;
  Landmarks truth_landmarks;
  if (fs::is_directory(truth_path)) {
    const sim::Truth t = sim::read_truth_json((truth_path / "landmarks.json").string());
    truth = mesh::read_mesh((truth_path / t.mesh_file).string(), {false, ""});
    for (const auto& [name, l] : t.landmarks) truth_landmarks[name] = l.xyz_mm;
  } else {
    require_file(truth_path.string(), "--truth");
    truth = mesh::read_mesh(truth_path.string(), {false, ""});
  }
  // With a bare mesh as truth the face region comes from the reconstruction's own landmarks.
  const model::FaceRegion region =
      model::face_region(truth_landmarks.empty() ? rec_landmarks : truth_landmarks);
  model::ErrorReport e;
  try {  // the model layer speaks of "the reconstructed mesh": say which files were compared
    e = model::reconstruction_error(rec, truth, region, rec_landmarks, truth_landmarks);
  } catch (const std::exception& ex) {
    throw std::runtime_error("eval of " + (dir / "head.obj").string() + " against " +
                             truth_path.string() + ": " + ex.what());
  }
  const mesh::TriMesh colored =
      model::error_colored(rec, model::signed_distances(rec.vertices, truth), range);
  mesh::write_mesh(colored, (dir / "error.ply").string());
  const cv::Mat picture = error_picture(colored, folder.rig.front);
  io::write_image_atomically((dir / "error.png").string(), picture);
  const nlohmann::json j = {
      {"relative_error", e.relative},
      {"mean_mm", e.mean_mm},
      {"rms_mm", e.rms_mm},
      {"max_mm", e.max_mm},
      {"diagonal_mm", e.diagonal_mm},
      {"samples", e.samples},
      {"landmark_mean_mm", e.landmark_mean_mm},
      {"landmark_mm", e.landmark_mm},
      {"truth", truth_path.string()},
      {"region",
       {{"y_top", region.y_top}, {"y_bottom", region.y_bottom}, {"z_min", region.z_min}}}};
  io::write_text_atomically((dir / "eval.json").string(), j.dump(2) + "\n");
  std::printf(
      "eval: relative error %.3f%% (mean %.2f mm / diagonal %.1f mm), landmarks %.2f mm "
      "mean over %zu\n",
      100 * e.relative, e.mean_mm, e.diagonal_mm, e.landmark_mean_mm, e.landmark_mm.size());
  return 0;
}

}  // namespace orthoface::app
