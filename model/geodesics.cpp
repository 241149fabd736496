#include "model/geodesics.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>

namespace orthoface::model {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct QueueItem {
  double d;
  int v;
  bool operator>(const QueueItem& o) const { return d > o.d; }
};
using MinQueue = std::priority_queue<QueueItem, std::vector<QueueItem>, std::greater<>>;

// Compressed vertex -> incident triangle lists.
struct Incidence {
  std::vector<int> start, tris;
};

Incidence incidence(const TriMesh& mesh) {
  const size_t n = mesh.vertices.size();
  Incidence inc;
  inc.start.assign(n + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++inc.start[t[k] + 1];
  for (size_t i = 0; i < n; ++i) inc.start[i + 1] += inc.start[i];
  inc.tris.resize(inc.start[n]);
  std::vector<int> fill(inc.start.begin(), inc.start.end() - 1);
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) inc.tris[fill[mesh.triangles[f][k]]++] = static_cast<int>(f);
  return inc;
}

void check_sources(const TriMesh& mesh, const std::vector<int>& sources, const char* what,
                   const GeodesicOptions& options) {
  check_mesh(mesh, what);
  options.check();
  if (sources.empty()) throw std::invalid_argument(std::string(what) + ": no source vertex");
  for (int s : sources)
    if (s < 0 || s >= static_cast<int>(mesh.vertices.size()))
      throw std::invalid_argument(std::string(what) + ": source vertex " + std::to_string(s) +
                                  " out of range [0, " + std::to_string(mesh.vertices.size()) +
                                  ")");
}

// Distance at C through the edge AB of triangle ABC, given dA, dB and the edge lengths. The
// known vertices are unfolded into the plane (A at origin, B on +x, C above) and the source
// they imply is the circle intersection below AB; if the straight ray from it to C crosses AB
// the distance is exact for a planar patch, otherwise the edge paths bound it. Lengths only, so
// no square root is spent on positions.
double triangle_update(double ab, double ac, double bc, double da, double db) {
  const double edge_bound = std::min(da + ac, db + bc);
  if (ab <= 0.0) return edge_bound;
  const double cx = (ac * ac + ab * ab - bc * bc) / (2.0 * ab);
  const double cy2 = ac * ac - cx * cx;
  if (cy2 <= 1e-18 * ac * ac) return edge_bound;  // degenerate triangle
  const double cy = std::sqrt(cy2);
  const double sx = (da * da - db * db + ab * ab) / (2.0 * ab);
  const double sy2 = da * da - sx * sx;
  if (sy2 < 0.0) return edge_bound;  // |dA - dB| > |AB|: no consistent planar source
  const double sy = -std::sqrt(sy2);
  const double t = -sy / (cy - sy);  // where the ray S->C meets y = 0
  const double x = sx + t * (cx - sx);
  if (x < 0.0 || x > ab) return edge_bound;
  return std::min(edge_bound, std::sqrt((cx - sx) * (cx - sx) + (cy - sy) * (cy - sy)));
}

// Rows [0, n) of a matrix filled by `fill_row(worker, row)` on all hardware threads, each worker
// with its own scratch state made by `make_worker()`.
template <class MakeWorker, class FillRow>
void parallel_rows(int n, MakeWorker make_worker, FillRow fill_row) {
  const int threads = std::clamp(int(std::thread::hardware_concurrency()), 1, std::max(1, n / 64));
  std::atomic<int> next{0};
  auto run = [&] {
    auto worker = make_worker();
    for (int row = next++; row < n; row = next++) fill_row(worker, row);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(run);
  run();
  for (auto& t : pool) t.join();
}

}  // namespace

void GeodesicOptions::check() const {
  if (!(max_distance > 0.0))
    throw std::invalid_argument("GeodesicOptions: max_distance must be > 0, got " +
                                std::to_string(max_distance));
}

std::vector<double> geodesic_distances(const TriMesh& mesh, const std::vector<int>& sources,
                                       const GeodesicOptions& options) {
  check_sources(mesh, sources, "geodesic_distances", options);
  return GeodesicSolver(mesh).distances(sources, options);
}

GeodesicSolver::GeodesicSolver(const TriMesh& mesh) {
  check_mesh(mesh, "GeodesicSolver");
  vertices_ = mesh.vertices;
  triangles_ = mesh.triangles;
  Incidence inc = incidence(mesh);
  start_ = std::move(inc.start);
  tris_ = std::move(inc.tris);
  edge_lengths_.reserve(triangles_.size());
  for (const auto& t : triangles_)
    edge_lengths_.push_back({(vertices_[t[1]] - vertices_[t[2]]).norm(),
                             (vertices_[t[2]] - vertices_[t[0]]).norm(),
                             (vertices_[t[0]] - vertices_[t[1]]).norm()});
  dist_.assign(vertices_.size(), kInf);
  done_.assign(vertices_.size(), 0);
}

std::vector<std::pair<int, double>> GeodesicSolver::reached(const std::vector<int>& sources,
                                                            const GeodesicOptions& options) {
  std::vector<std::pair<int, double>> seeds;
  for (int s : sources) seeds.emplace_back(s, 0.0);
  return reached_from_seeds(seeds, options);
}

std::vector<std::pair<int, double>> GeodesicSolver::reached_from_seeds(
    const std::vector<std::pair<int, double>>& seeds, const GeodesicOptions& options) {
  options.check();
  if (seeds.empty()) throw std::invalid_argument("GeodesicSolver: no source vertex");
  for (const auto& [s, d0] : seeds) {
    if (s < 0 || s >= static_cast<int>(vertices_.size()))
      throw std::invalid_argument("GeodesicSolver: source vertex " + std::to_string(s) +
                                  " out of range [0, " + std::to_string(vertices_.size()) + ")");
    if (!(d0 >= 0.0) || !std::isfinite(d0))
      throw std::invalid_argument("GeodesicSolver: seed distance must be finite and >= 0");
  }
  std::vector<int> touched;
  std::vector<std::pair<int, double>> out;
  MinQueue queue;
  for (const auto& [s, d0] : seeds) {
    if (dist_[s] == kInf) touched.push_back(s);
    if (d0 >= dist_[s]) continue;
    dist_[s] = d0;
    queue.push({d0, s});
  }
  while (!queue.empty()) {
    const QueueItem top = queue.top();
    queue.pop();
    if (done_[top.v] || top.d > dist_[top.v]) continue;
    if (top.d > options.max_distance) break;
    done_[top.v] = 1;
    out.emplace_back(top.v, top.d);
    const int v = top.v;
    for (int k = start_[v]; k < start_[v + 1]; ++k) {
      const auto& t = triangles_[tris_[k]];
      const auto& len = edge_lengths_[tris_[k]];  // len[j]: the edge opposite corner j
      const int i = t[0] == v ? 0 : (t[1] == v ? 1 : 2), ia = (i + 1) % 3, ib = (i + 2) % 3;
      const int a = t[ia], b = t[ib];
      // Update each unfinished corner from v alone or from v and the other finished corner.
      for (const auto& [target, other, l_vo, l_vt, l_ot] :
           {std::tuple{a, b, len[ia], len[ib], len[i]}, std::tuple{b, a, len[ib], len[ia], len[i]}}) {
        if (done_[target]) continue;
        const double d = done_[other]
                             ? triangle_update(l_vo, l_vt, l_ot, dist_[v], dist_[other])
                             : dist_[v] + l_vt;
        if (d < dist_[target]) {
          if (dist_[target] == kInf) touched.push_back(target);
          dist_[target] = d;
          queue.push({d, target});
        }
      }
    }
  }
  for (int v : touched) dist_[v] = kInf, done_[v] = 0;
  return out;
}

std::vector<double> GeodesicSolver::distances(const std::vector<int>& sources,
                                              const GeodesicOptions& options) {
  std::vector<double> d(vertices_.size(), kInf);
  for (const auto& [v, dv] : reached(sources, options)) d[v] = dv;
  return d;
}

std::vector<std::vector<int>> vertex_neighbors(const TriMesh& mesh) {
  check_mesh(mesh, "vertex_neighbors");
  std::vector<std::vector<int>> nb(mesh.vertices.size());
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      nb[t[k]].push_back(t[(k + 1) % 3]);
      nb[t[k]].push_back(t[(k + 2) % 3]);
    }
  for (auto& row : nb) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  return nb;
}

namespace {

std::vector<double> dijkstra(const TriMesh& mesh, const std::vector<std::vector<int>>& nb,
                             const std::vector<int>& sources, double max_distance) {
  std::vector<double> dist(mesh.vertices.size(), kInf);
  MinQueue queue;
  for (int s : sources) {
    dist[s] = 0.0;
    queue.push({0.0, s});
  }
  while (!queue.empty()) {
    const QueueItem top = queue.top();
    queue.pop();
    if (top.d > dist[top.v]) continue;
    if (top.d > max_distance) break;
    for (int u : nb[top.v]) {
      const double d = top.d + (mesh.vertices[u] - mesh.vertices[top.v]).norm();
      if (d < dist[u]) {
        dist[u] = d;
        queue.push({d, u});
      }
    }
  }
  for (double& d : dist)
    if (d > max_distance) d = kInf;
  return dist;
}

void check_matrix_size(const TriMesh& mesh, int max_vertices, const char* what) {
  check_mesh(mesh, what);
  if (static_cast<long long>(mesh.vertices.size()) > max_vertices)
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(mesh.vertices.size()) +
                                " vertices exceed the dense-matrix limit of " +
                                std::to_string(max_vertices) +
                                " (use single-source distances instead)");
}

}  // namespace

std::vector<double> edge_graph_distances(const TriMesh& mesh, const std::vector<int>& sources,
                                         const GeodesicOptions& options) {
  check_sources(mesh, sources, "edge_graph_distances", options);
  return dijkstra(mesh, vertex_neighbors(mesh), sources, options.max_distance);
}

DistanceMatrix geodesic_matrix(const TriMesh& mesh, GeodesicMethod method, int max_vertices) {
  check_matrix_size(mesh, max_vertices, "geodesic_matrix");
  const int n = static_cast<int>(mesh.vertices.size());
  DistanceMatrix m{n, std::vector<float>(static_cast<size_t>(n) * n)};
  const auto nb = vertex_neighbors(mesh);
  const GeodesicSolver prototype(mesh);  // copied per worker: its scratch arrays are per run
  parallel_rows(
      n, [&] { return prototype; },
      [&](GeodesicSolver& solver, int s) {
        const std::vector<double> row = method == GeodesicMethod::kEdgeGraph
                                            ? dijkstra(mesh, nb, {s}, kInf)
                                            : solver.distances({s});
        std::copy(row.begin(), row.end(), m.values.begin() + static_cast<size_t>(s) * n);
      });
  return m;
}

DistanceMatrix euclidean_matrix(const TriMesh& mesh, int max_vertices) {
  check_matrix_size(mesh, max_vertices, "euclidean_matrix");
  const int n = static_cast<int>(mesh.vertices.size());
  DistanceMatrix m{n, std::vector<float>(static_cast<size_t>(n) * n)};
  std::vector<Eigen::Vector3f> p;
  for (const auto& v : mesh.vertices) p.push_back(v.cast<float>());
  parallel_rows(
      n, [] { return 0; },
      [&](int, int i) {
        float* row = m.values.data() + static_cast<size_t>(i) * n;
        for (int j = 0; j < n; ++j) row[j] = (p[i] - p[j]).norm();
      });
  return m;
}

}  // namespace orthoface::model
