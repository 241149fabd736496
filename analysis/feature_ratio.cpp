// Seed 000 §VI.C / §VI.G: vertices close in Euclidean distance but far apart along the surface.
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "analysis/geodesics.h"
#include "analysis/mpeg4_features.h"
#include "analysis/parallel_rows.h"
#include "analysis/point_grid.h"

namespace orthoface::analysis {

void FeatureOptions::check() const {
  auto bad = [](const std::string& field, double v) {
    throw std::invalid_argument("FeatureOptions: " + field + " out of range: " + std::to_string(v));
  };
  if (!(neighbourhood > 0.0 && neighbourhood < 0.5)) bad("neighbourhood", neighbourhood);
  if (!(ratio_threshold > 1.0 && ratio_threshold < ratio_cap))
    bad("ratio_threshold", ratio_threshold);
  if (!(ratio_cap > 1.0 && ratio_cap <= 20.0)) bad("ratio_cap", ratio_cap);
  if (!(dense_area > 0.0 && dense_area < 0.5)) bad("dense_area", dense_area);
  if (max_sources < 10) bad("max_sources", max_sources);
  if (!(plane_band > 0.0 && plane_band < 0.5)) bad("plane_band", plane_band);
}

namespace {

// Farthest-point sample of `count` vertex indices (deterministic: starts at vertex 0).
std::vector<int> farthest_point_sample(const std::vector<Eigen::Vector3d>& p, int count) {
  const Eigen::Index n = static_cast<Eigen::Index>(p.size());
  Eigen::ArrayXd x(n), y(n), z(n);  // coordinates as arrays: one vectorised pass per sample
  for (Eigen::Index i = 0; i < n; ++i) x[i] = p[i].x(), y[i] = p[i].y(), z[i] = p[i].z();
  Eigen::ArrayXd d = Eigen::ArrayXd::Constant(n, std::numeric_limits<double>::infinity());
  std::vector<int> out;
  Eigen::Index next = 0;
  for (int k = 0; k < count; ++k) {
    out.push_back(int(next));
    d = d.min((x - x[next]).square() + (y - y[next]).square() + (z - z[next]).square());
    d.maxCoeff(&next);  // the first of equal maxima
  }
  return out;
}

}  // namespace

double pose_free_size(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "pose_free_size");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& v : mesh.vertices) mean += v / double(mesh.vertices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& v : mesh.vertices) cov += (v - mean) * (v - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Eigen::AlignedBox3d box;  // box along the principal axes: the same in every pose
  for (const auto& v : mesh.vertices) box.extend(es.eigenvectors().transpose() * (v - mean));
  return box.diagonal().norm();
}

std::vector<double> geodesic_euclidean_ratio(const mesh::TriMesh& mesh,
                                             const FeatureOptions& options) {
  mesh::check_mesh(mesh, "geodesic_euclidean_ratio");
  options.check();
  const auto& p = mesh.vertices;
  const double r = options.neighbourhood * pose_free_size(mesh);
  if (!(r > 0.0)) throw std::invalid_argument("geodesic_euclidean_ratio: mesh has no extent");
  std::vector<int> all(p.size());
  std::iota(all.begin(), all.end(), 0);
  const detail::PointGrid grid(p, r, all);
  const std::vector<int> sources =
      int(p.size()) <= options.max_sources ? all : farthest_point_sample(p, options.max_sources);
  GeodesicOptions go;
  go.max_distance = options.ratio_cap * r;
  // Sources split into chunks over the thread pool, each with its own solver and ratio array; the
  // arrays are merged by maximum (order-free, so the result does not depend on the split).
  struct Worker {
    GeodesicSolver solver;
    std::vector<double> geo, ratio;
  };
  const int n_sources = static_cast<int>(sources.size());
  std::vector<std::vector<double>> ratios(detail::row_chunks(n_sources));
  detail::parallel_rows(
      n_sources,
      [&](int) {
        return Worker{GeodesicSolver(mesh), std::vector<double>(p.size(), -1.0),
                      std::vector<double>(p.size(), 1.0)};
      },
      [&](Worker& w, int k) {
        const int s = sources[k];
        const auto reached = w.solver.reached({s}, go);
        for (const auto& [v, d] : reached) w.geo[v] = d;
        grid.for_each_near(p[s], r, [&](int u) {
          const double e = (p[u] - p[s]).norm();
          if (u == s || e <= 0.0) return;
          const double g = w.geo[u] >= 0.0 ? w.geo[u] : go.max_distance;
          const double q = std::min(options.ratio_cap, g / e);
          w.ratio[s] = std::max(w.ratio[s], q);
          w.ratio[u] = std::max(w.ratio[u], q);
        });
        for (const auto& [v, d] : reached) w.geo[v] = -1.0;
      },
      [&](Worker& w, int index) { ratios[index] = std::move(w.ratio); });
  std::vector<double> ratio(p.size(), 1.0);
  for (const auto& part : ratios)
    for (size_t v = 0; v < part.size(); ++v) ratio[v] = std::max(ratio[v], part[v]);
  return ratio;
}

}  // namespace orthoface::analysis
