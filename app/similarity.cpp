// orthoface similarity: seed 003 face similarity (geodesic network + curvature correlations).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "analysis/similarity.h"
#include "app/analysis_views.h"
#include "app/cli.h"
#include "app/commands.h"
#include "io/atomic_file.h"
#include "mesh/mesh_io.h"

namespace orthoface::app {
namespace {

Command similarity_command() {
  return {"similarity",
          "Compare face meshes in the standard pose (+z out of the face, +y up) by seed 003: "
          "nose tip, 8 iso-geodesics and M radial geodesics as corresponding points, mean / "
          "Gaussian curvature, shape index and curvedness averaged over 0/1/2 rings (100/10/1), "
          "|correlation| of each. Two meshes: four scores; more: matrices (CSV + heat map).",
          "orthoface similarity A B [C ...] [-o DIR] [options]",
          {{"o", true, "DIR  write similarity_<metric>.csv and similarity_shape_index.png"},
           {"geodesics", true, "M  radial geodesics (default 16)"},
           {"radius", true, "R  outermost iso-geodesic in mesh units (default 80)"}},
          1000};
}

const char* kMetrics[] = {"mean", "gaussian", "shape_index", "curvedness"};

double metric(const analysis::SimilarityScores& s, int k) {
  return k == 0 ? s.mean : k == 1 ? s.gaussian : k == 2 ? s.shape_index : s.curvedness;
}

cv::Mat heat_map(const std::vector<std::vector<double>>& m) {
  const int n = int(m.size()), cell = std::max(8, 480 / n);
  cv::Mat img(n * cell, n * cell, CV_8UC3);
  double lo = 1.0;
  for (const auto& row : m)
    for (double v : row)
      if (std::isfinite(v)) lo = std::min(lo, v);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double t = std::isfinite(m[i][j]) ? (m[i][j] - lo) / std::max(1e-9, 1.0 - lo) : 0.0;
      const Eigen::Vector3d c = heat_rgb(t) * 255.0;  // seed 003: 1 red, the minimum blue
      cv::rectangle(img, {j * cell, i * cell, cell, cell}, cv::Scalar(c.z(), c.y(), c.x()),
                    cv::FILLED);
    }
  return img;
}

}  // namespace

int run_similarity(int argc, char** argv) {
  const Command cmd = similarity_command();
  const Args args = parse_args(cmd, argc, argv);
  if (args.help) return print_help(cmd), 0;
  const auto& files = args.positional;
  if (files.size() < 2) throw std::invalid_argument("similarity: needs at least two meshes");
  if (files.size() > 2 && !args.has("o"))
    throw std::invalid_argument("similarity: more than two meshes need -o DIR for the matrices");
  analysis::SimilarityOptions options;
  if (args.has("geodesics"))
    options.radial_geodesics = to_int("geodesics", args.get("geodesics"), 3, 360);
  if (args.has("radius")) options.radius = to_double("radius", args.get("radius"), 1e-9, 1e9);
  options.check();
  std::vector<analysis::FaceSignature> sig;
  for (const auto& f : files) {
    require_file(f, "mesh");
    const mesh::TriMesh m = mesh::read_mesh(f);  // its errors name the file
    try {
      sig.push_back(analysis::face_signature(m, options));
      const std::string problem = analysis::signature_problem(sig.back());
      if (!problem.empty()) throw std::runtime_error(problem);  // a NaN score otherwise
    } catch (const std::exception& e) {
      throw std::runtime_error("mesh " + f + ": " + e.what());
    }
    for (const auto& w : sig.back().warnings) std::printf("%s: %s\n", f.c_str(), w.c_str());
  }
  const size_t n = sig.size();
  std::vector<std::vector<analysis::SimilarityScores>> s(
      n, std::vector<analysis::SimilarityScores>(n));
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) s[i][j] = s[j][i] = analysis::similarity(sig[i], sig[j]);
  if (n == 2)
    std::printf("similarity %s %s: mean %.6f gaussian %.6f shape_index %.6f curvedness %.6f\n",
                files[0].c_str(), files[1].c_str(), s[0][1].mean, s[0][1].gaussian,
                s[0][1].shape_index, s[0][1].curvedness);
  if (!args.has("o")) return 0;
  const std::filesystem::path dir = args.get("o");
  io::FileGroup outputs;  // all of them or none (a full disk half-way)
  prepare_output_dir(dir.string(), &outputs);
  for (int k = 0; k < 4; ++k) {
    std::string csv = "mesh";
    for (const auto& f : files) csv += "," + f;
    csv += "\n";
    std::vector<std::vector<double>> m(n, std::vector<double>(n));
    for (size_t i = 0; i < n; ++i) {
      csv += files[i];
      for (size_t j = 0; j < n; ++j) {
        m[i][j] = metric(s[i][j], k);
        csv += "," + std::to_string(m[i][j]);
      }
      csv += "\n";
    }
    const auto path = dir / (std::string("similarity_") + kMetrics[k] + ".csv");
    io::write_text_atomically(path.string(), csv);
    if (k == 2)
      io::write_image_atomically((dir / "similarity_shape_index.png").string(), heat_map(m));
  }
  outputs.commit();
  std::printf("similarity: %zu meshes -> %s\n", n, dir.string().c_str());
  return 0;
}

}  // namespace orthoface::app
