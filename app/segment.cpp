// orthoface segment: weight-motion areas around feature points (seed 001).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "analysis/motion_areas.h"
#include "app/analysis_views.h"
#include "app/cli.h"
#include "app/commands.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"

namespace orthoface::app {
namespace {

Command segment_command() {
  return {
      "segment",
      "Split a face mesh into weight-motion areas (seed 001): every vertex joins the feature "
      "point at the smallest great-circle distance around the head centre. Writes the "
      "membership table (count, %), a PLY with one colour per area, a picture and, with "
      "--smooth, per-point weights falling off with geodesic distance.",
      "orthoface segment MESH --points FP.json -o DIR [options]",
      {{"points", true, "FILE  feature points JSON (orthoface features output or {name: [x,y,z]})"},
       {"o", true, "DIR  output folder"},
       {"centre", true, "X,Y,Z  head centre (default 0,0,0: the head frame's ear midpoint)"},
       {"smooth", true, "SIGMA  also write weights.json, Gaussian falloff (mesh units)"},
       {"any-names", false, "accept point names that are not MPEG-4 or landmark names"}},
      1};
}

Eigen::Vector3d parse_xyz(const std::string& flag, const std::string& text) {
  std::istringstream in(text);
  Eigen::Vector3d v;
  char c1 = 0, c2 = 0;
  if (!(in >> v.x() >> c1 >> v.y() >> c2 >> v.z()) || c1 != ',' || c2 != ',' || !v.allFinite())
    throw std::invalid_argument("--" + flag + ": expected X,Y,Z, got '" + text + "'");
  return v;
}

}  // namespace

int run_segment(int argc, char** argv) {
  const Command cmd = segment_command();
  const Args args = parse_args(cmd, argc, argv);
  if (args.help) return print_help(cmd), 0;
  if (args.positional.size() != 1 || !args.has("points") || !args.has("o"))
    throw std::invalid_argument("segment: needs MESH, --points FP.json and -o DIR");
  analysis::SegmentationOptions options;
  if (args.has("centre")) options.centre = parse_xyz("centre", args.get("centre"));
  if (args.has("smooth")) {
    options.smooth_weights = true;
    options.falloff = to_double("smooth", args.get("smooth"), 1e-9, 1e9);
  }
  options.check();
  require_file(args.positional[0], "mesh");
  require_file(args.get("points"), "feature-point file");
  const mesh::TriMesh mesh = mesh::read_mesh(args.positional[0]);
  const auto points = analysis::read_feature_points(args.get("points"), args.has("any-names"));
  const analysis::Segmentation s = analysis::segment_by_feature_points(mesh, points, options);
  const std::filesystem::path dir = args.get("o");
  io::FileGroup outputs;  // all of them or none (a full disk half-way)
  prepare_output_dir(dir.string(), &outputs);
  std::string csv = "fp,name,n,percent\n";  // seed 001 Table V
  nlohmann::json table = nlohmann::json::array();
  for (size_t p = 0; p < points.size(); ++p) {
    csv += std::to_string(p + 1) + "," + points[p].name + "," + std::to_string(s.count[p]) + "," +
           std::to_string(s.percent[p]) + "\n";
    table.push_back(
        {{"fp", p + 1}, {"name", points[p].name}, {"n", s.count[p]}, {"percent", s.percent[p]}});
  }
  io::write_text_atomically((dir / "membership.csv").string(), csv);
  io::write_text_atomically(
      (dir / "membership.json").string(),
      nlohmann::json{{"mesh", args.positional[0]}, {"areas", table}, {"label", s.label}}.dump(1) +
          "\n");
  mesh::TriMesh colored;
  colored.vertices = mesh.vertices, colored.triangles = mesh.triangles;
  for (int l : s.label) colored.colors.push_back(label_rgb(l));
  mesh::write_mesh(colored, (dir / "areas.ply").string());
  std::vector<Marker> markers;
  for (const auto& p : points) markers.push_back({p.position, p.name});
  io::write_image_atomically(
      (dir / "segment.png").string(),
      render_view(colored,
                  view_camera(colored, -Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), 600),
                  markers));
  if (options.smooth_weights) {
    nlohmann::json w;
    for (size_t p = 0; p < points.size(); ++p) {
      nlohmann::json pairs = nlohmann::json::array();
      for (size_t v = 0; v < mesh.vertices.size(); ++v)
        if (s.weights[p][v] > 1e-4) pairs.push_back({v, s.weights[p][v]});
      w[points[p].name] = pairs;
    }
    io::write_text_atomically((dir / "weights.json").string(), w.dump() + "\n");
  }
  outputs.commit();
  std::printf("segment: %zu vertices into %zu areas -> %s\n", mesh.vertices.size(), points.size(),
              dir.string().c_str());
  return 0;
}

}  // namespace orthoface::app
