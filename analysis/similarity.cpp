// Seed 003: geodesic network around the nose tip + curvature metrics -> similarity scores.
#include "analysis/similarity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "analysis/analysis_mesh.h"
#include "analysis/curvature.h"
#include "analysis/geodesics.h"

namespace orthoface::analysis {

void SimilarityOptions::check() const {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("SimilarityOptions: " + what);
  };
  if (iso_geodesics < 1 || iso_geodesics > 100) bad("iso_geodesics must be in [1, 100]");
  if (radial_geodesics < 3 || radial_geodesics > 360) bad("radial_geodesics must be in [3, 360]");
  if (!(radius > 0.0) || !std::isfinite(radius)) bad("radius must be > 0");
  if (!(w0 >= 0 && w1 >= 0 && w2 >= 0 && w0 + w1 + w2 > 0)) bad("weights must be >= 0, not all 0");
  if (!(view_axis.norm() > 0) || !(up_axis.norm() > 0) || !view_axis.allFinite() ||
      !up_axis.allFinite() || view_axis.normalized().cross(up_axis.normalized()).norm() < 0.1)
    bad("view_axis and up_axis must be non-zero and not parallel");
}

namespace {

// Vertices on an open boundary (an edge used by one triangle).
std::vector<int> boundary_vertices(const mesh::TriMesh& m) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  std::vector<int> out;
  for (const auto& [e, n] : uses)
    if (n == 1) out.push_back(e.first), out.push_back(e.second);
  return out;
}

int nearest_vertex(const mesh::TriMesh& m, const Eigen::Vector3d& p) {
  int best = 0;
  for (size_t v = 1; v < m.vertices.size(); ++v)
    if ((m.vertices[v] - p).squaredNorm() < (m.vertices[best] - p).squaredNorm()) best = int(v);
  return best;
}

// Target vertex of each radial geodesic on the outermost iso-geodesic: equal angles in the
// tangent plane of the nose tip, clockwise from up seen from the front (§4.3 eq. 3).
std::vector<int> radial_targets(const mesh::TriMesh& m, const std::vector<double>& d,
                                const Eigen::Vector3d& tip, double outer,
                                const SimilarityOptions& o) {
  const Eigen::Vector3d view = o.view_axis.normalized();
  const Eigen::Vector3d up = (o.up_axis - o.up_axis.dot(view) * view).normalized();
  const Eigen::Vector3d right = up.cross(view);
  std::vector<int> out;
  for (int i = 0; i < o.radial_geodesics; ++i) {
    const double want = 2.0 * M_PI * i / o.radial_geodesics;
    int best = -1;
    double best_cost = 1e300;
    for (size_t v = 0; v < m.vertices.size(); ++v) {
      if (!std::isfinite(d[v]) || std::abs(d[v] - outer) > 0.06 * outer) continue;
      const Eigen::Vector3d q = m.vertices[v] - tip;
      double diff = std::abs(std::remainder(std::atan2(q.dot(right), q.dot(up)) - want, 2 * M_PI));
      const double cost = diff + 0.2 * std::abs(d[v] - outer) / outer;
      if (cost < best_cost) best_cost = cost, best = int(v);
    }
    if (best < 0)
      throw std::runtime_error("face_signature: no surface at the outermost iso-geodesic");
    out.push_back(best);
  }
  return out;
}

// Where a traced geodesic crosses each iso level j * width (j = 1..n), as surface points.
std::vector<Eigen::Vector3d> crossings(const GeodesicPath& path, double width, int n) {
  std::vector<Eigen::Vector3d> out;
  for (int j = 1; j <= n; ++j) {
    const double level = j * width;
    Eigen::Vector3d p = path.points.front();  // path runs from the target (far) to the source
    for (size_t k = 0; k + 1 < path.points.size(); ++k) {
      const double a = path.distances[k], b = path.distances[k + 1];
      if (a >= level && b <= level) {
        const double t = a > b ? (a - level) / (a - b) : 0.0;
        p = path.points[k] + t * (path.points[k + 1] - path.points[k]);
        break;
      }
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace

FaceSignature face_signature(const mesh::TriMesh& mesh, const SimilarityOptions& options) {
  options.check();
  const AnalysisMesh am = analysis_mesh(mesh, "face_signature");
  const mesh::TriMesh& m = am.mesh;
  FaceSignature sig;
  sig.warnings = am.warnings;
  // §4.1: the nose tip is the point furthest along the viewing axis. A soft maximum (1 mm
  // temperature) makes it move continuously with the surface instead of jumping between
  // vertices; distances start from that point through its nearest vertex and 1-ring.
  const Eigen::Vector3d view = options.view_axis.normalized();
  int nose = 0;
  for (size_t v = 1; v < m.vertices.size(); ++v)
    if (m.vertices[v].dot(view) > m.vertices[nose].dot(view)) nose = int(v);
  const double zmax = m.vertices[nose].dot(view), tau = 0.0125 * options.radius;
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  double wsum = 0.0;
  for (const auto& p : m.vertices) {
    const double w = std::exp((p.dot(view) - zmax) / tau);
    tip += w * p, wsum += w;
  }
  tip /= wsum;
  nose = nearest_vertex(m, tip);
  const auto ring = vertex_neighbors(m)[nose];
  std::vector<std::pair<int, double>> seeds{{nose, (m.vertices[nose] - tip).norm()}};
  for (int u : ring) seeds.emplace_back(u, (m.vertices[u] - tip).norm());
  GeodesicSolver solver(m);
  const std::vector<double> d = [&] {
    std::vector<double> out(m.vertices.size(), std::numeric_limits<double>::infinity());
    for (const auto& [v, dv] : solver.reached_from_seeds(seeds)) out[v] = dv;
    return out;
  }();
  double outer = options.radius;
  for (int b : boundary_vertices(m)) outer = std::min(outer, d[b]);  // §4.2 eq. 2
  if (outer < options.radius)
    sig.warnings.push_back("network radius limited by the mesh boundary to " +
                           std::to_string(outer));
  if (!(outer >= 0.05 * options.radius))
    throw std::runtime_error("face_signature: the mesh boundary is " + std::to_string(outer) +
                             " from the nose tip, too close for a network of radius " +
                             std::to_string(options.radius));
  const int n = options.iso_geodesics;
  sig.width = outer / n;
  sig.nose_tip = am.original_index[nose];
  const Curvature c = principal_curvatures(m);
  std::vector<double> H(m.vertices.size()), K(H.size()), S(H.size()), R(H.size());
  for (size_t v = 0; v < H.size(); ++v) {
    H[v] = mean_curvature(c.k1[v], c.k2[v]);
    K[v] = gaussian_curvature(c.k1[v], c.k2[v]);
    S[v] = shape_index(c.k1[v], c.k2[v]);
    R[v] = curvedness(c.k1[v], c.k2[v]);
  }
  const auto nb = vertex_neighbors(m);
  // §5.3 eqs. 15-16: 100 / 10 / 1 over each vertex, its 1-ring and its 2-ring.
  std::vector<double> Ha(H.size()), Ka(H.size()), Sa(H.size()), Ra(H.size());
  for (size_t v = 0; v < H.size(); ++v) {
    Ha[v] = ring_average(nb, H, int(v), options.w0, options.w1, options.w2);
    Ka[v] = ring_average(nb, K, int(v), options.w0, options.w1, options.w2);
    Sa[v] = ring_average(nb, S, int(v), options.w0, options.w1, options.w2);
    Ra[v] = ring_average(nb, R, int(v), options.w0, options.w1, options.w2);
  }
  for (int target : radial_targets(m, d, tip, outer, options)) {
    const GeodesicPath path = geodesic_path(m, d, target);            // §4.4
    for (const Eigen::Vector3d& p : crossings(path, sig.width, n)) {  // §4.5 eq. 5
      const int v = nearest_vertex(m, p);
      sig.network.push_back(am.original_index[v]);
      sig.network_points.push_back(p);
      // The crossing lies between vertices: inverse-square-distance blend of the nearest
      // vertex and its 1-ring, so the value moves smoothly with the network point.
      double wsum = 0, h = 0, k = 0, si = 0, r = 0;
      std::vector<int> around = nb[v];
      around.push_back(v);
      for (int u : around) {
        const double w = 1.0 / ((m.vertices[u] - p).squaredNorm() + 1e-6 * sig.width * sig.width);
        wsum += w, h += w * Ha[u], k += w * Ka[u], si += w * Sa[u], r += w * Ra[u];
      }
      sig.mean.push_back(h / wsum);
      sig.gaussian.push_back(k / wsum);
      sig.shape_index.push_back(si / wsum);
      sig.curvedness.push_back(r / wsum);
    }
  }
  return sig;
}

namespace {

double mean_of(const std::vector<double>& a) {
  double m = 0;
  for (double x : a) m += x / double(a.size());
  return m;
}

// The sum of squared deviations from the mean `m` of `a` is large enough to divide by: more
// than rounding noise of the values themselves (a constant metric is a few ulps from its mean).
bool varies(const std::vector<double>& a, double m) {
  double saa = 0;
  for (double x : a) saa += (x - m) * (x - m);
  return std::isfinite(saa) && saa > 1e-24 * std::max(1.0, m * m) * double(a.size());
}

double abs_correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double ma = mean_of(a), mb = mean_of(b);
  if (!varies(a, ma) || !varies(b, mb)) return std::numeric_limits<double>::quiet_NaN();
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i)
    sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma),
        sbb += (b[i] - mb) * (b[i] - mb);
  // seed 003 eq. 17, absolute value (§6); Cauchy-Schwarz bounds it by 1 up to rounding
  return std::min(1.0, std::abs(sab / (std::sqrt(saa) * std::sqrt(sbb))));
}

}  // namespace

std::string signature_problem(const FaceSignature& s) {
  if (s.mean.empty()) return "no network points";
  const std::pair<const char*, const std::vector<double>*> metrics[] = {
      {"mean curvature", &s.mean},
      {"Gaussian curvature", &s.gaussian},
      {"shape index", &s.shape_index},
      {"curvedness", &s.curvedness}};
  for (const auto& [name, values] : metrics) {
    if (values->size() != s.mean.size())
      return std::string("its ") + name + " has " + std::to_string(values->size()) +
             " values for " + std::to_string(s.mean.size()) + " network points";
    for (double x : *values)
      if (!std::isfinite(x)) return std::string("its ") + name + " is not finite everywhere";
    if (!varies(*values, mean_of(*values)))
      return std::string("its ") + name +
             " is the same at every network point (a sphere or a plane?): a similarity to it "
             "is undefined";
  }
  return "";
}

SimilarityScores similarity(const FaceSignature& a, const FaceSignature& b) {
  if (a.mean.size() != b.mean.size() || a.mean.empty())
    throw std::invalid_argument("similarity: networks have " + std::to_string(a.mean.size()) +
                                " and " + std::to_string(b.mean.size()) +
                                " points (build both with the same options)");
  return {abs_correlation(a.mean, b.mean), abs_correlation(a.gaussian, b.gaussian),
          abs_correlation(a.shape_index, b.shape_index),
          abs_correlation(a.curvedness, b.curvedness)};
}

}  // namespace orthoface::analysis
