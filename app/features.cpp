// orthoface features: seed 000 key vertices, axes, symmetry plane and MPEG-4 feature points.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "analysis/mpeg4_features.h"
#include "app/analysis_views.h"
#include "app/cli.h"
#include "app/commands.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"

namespace orthoface::app {
namespace {

Command features_command() {
  return {"features",
          "Find the MPEG-4 feature points of a head mesh (seed 000): dense regions where the "
          "geodesic / Euclidean ratio is high, both ears, their midpoint, the nose tip, the local "
          "axes and symmetry plane, then peaks and troughs of the mid-plane and side-plane "
          "profiles. Works in any pose and scale; a face without ears reports what it lacks.",
          "orthoface features MESH -o DIR [options]",
          {{"o", true, "DIR  output folder: features.json, clusters.csv, features.png"},
           {"neighbourhood", true, "F  ratio radius as a fraction of the mesh size (default 0.03)"},
           {"size", true, "N  picture tile size in pixels (default 400)"}},
          1};
}

cv::Mat picture(const mesh::TriMesh& mesh, const analysis::FeatureReport& r, int size) {
  mesh::TriMesh m;
  m.vertices = mesh.vertices, m.triangles = mesh.triangles;
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    m.colors.push_back(r.cluster[v] >= 0 ? label_rgb(r.cluster[v])
                                         : Eigen::Vector3d(0.8, 0.8, 0.8));
  std::vector<Marker> markers;
  for (const auto& p : r.points) markers.push_back({p.position, p.name});
  const Eigen::Vector3d fwd =
      r.axes_found ? Eigen::Vector3d(r.axes.col(2)) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up =
      r.axes_found ? Eigen::Vector3d(r.axes.col(1)) : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d left = up.cross(fwd);
  std::vector<cv::Mat> views;
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(-fwd), Eigen::Vector3d(-left), Eigen::Vector3d(left)})
    views.push_back(render_view(m, view_camera(m, d, up, size), markers));
  cv::Mat out;
  cv::hconcat(views, out);
  return out;
}

}  // namespace

int run_features(int argc, char** argv) {
  const Command cmd = features_command();
  const Args args = parse_args(cmd, argc, argv);
  if (args.help) return print_help(cmd), 0;
  if (args.positional.size() != 1 || !args.has("o"))
    throw std::invalid_argument("features: needs MESH and -o DIR (orthoface features --help)");
  analysis::FeatureOptions options;
  if (args.has("neighbourhood"))
    options.neighbourhood = to_double("neighbourhood", args.get("neighbourhood"), 0.001, 0.45);
  const int size = args.has("size") ? to_int("size", args.get("size"), 64, 4096) : 400;
  options.check();
  const std::string path = args.positional[0];
  require_file(path, "mesh");
  const mesh::TriMesh mesh = mesh::read_mesh(path);
  const auto t0 = std::chrono::steady_clock::now();
  const analysis::FeatureReport r = analysis::mpeg4_features(mesh, options);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::filesystem::path dir = args.get("o");
  io::FileGroup outputs;  // all of them or none (a full disk half-way)
  prepare_output_dir(dir.string(), &outputs);
  nlohmann::json j = nlohmann::json::parse(analysis::feature_report_json(mesh, r));
  j["mesh"] = path;
  j["seconds"] = secs;
  io::write_text_atomically((dir / "features.json").string(), j.dump(2) + "\n");
  std::string csv = "vertex,cluster,ratio\n";  // seed 000's z_clusters
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    if (r.cluster[v] >= 0)
      csv += std::to_string(v) + "," + std::to_string(r.cluster[v]) + "," +
             std::to_string(r.ratio[v]) + "\n";
  io::write_text_atomically((dir / "clusters.csv").string(), csv);
  io::write_image_atomically((dir / "features.png").string(), picture(mesh, r, size));
  outputs.commit();
  std::printf("features: %zu points found, %zu missing / notes, %.2f s -> %s\n", r.points.size(),
              r.missing.size(), secs, dir.string().c_str());
  for (const auto& m : r.missing) std::printf("  %s\n", m.c_str());
  return 0;
}

}  // namespace orthoface::app
