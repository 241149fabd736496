#include "analysis/geodesics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>

#include "analysis/parallel_rows.h"

namespace orthoface::analysis {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_sources(const mesh::TriMesh& mesh, const std::vector<int>& sources, const char* what,
                   const GeodesicOptions& options) {
  mesh::check_mesh(mesh, what);
  options.check();
  if (sources.empty()) throw std::invalid_argument(std::string(what) + ": no source vertex");
  for (int s : sources)
    if (s < 0 || s >= static_cast<int>(mesh.vertices.size()))
      throw std::invalid_argument(std::string(what) + ": source vertex " + std::to_string(s) +
                                  " out of range [0, " + std::to_string(mesh.vertices.size()) +
                                  ")");
}

// Corner C unfolded into the plane of the edge AB: A at the origin, B at (ab, 0), C at (x, y)
// with y > 0, from the edge lengths; y = 0 if the triangle is degenerate.
std::pair<double, double> unfold(double ab, double ac, double bc) {
  if (!(ab > 0.0)) return {0.0, 0.0};
  const double cx = (ac * ac + ab * ab - bc * bc) / (2.0 * ab);
  const double cy2 = ac * ac - cx * cx;
  if (cy2 <= 1e-18 * ac * ac) return {0.0, 0.0};
  return {cx, std::sqrt(cy2)};
}

// Distance at C through the edge AB with A and B accepted (C unfolded at (cx, cy) as above). The
// source that dA, dB imply is placed below AB by circle intersection; if the straight ray from it
// to C crosses AB the distance is exact for a planar patch, otherwise the edge paths bound it
// (Kimmel & Sethian 1998 update with the unfolding of Surazhsky et al. 2005 §3). The crossing is
// tested without a division: x = (sx cy - sy cx) / (cy - sy) with cy - sy > 0.
inline double planar_update(double da, double db, double ab, double ac, double bc, double cx,
                            double cy) {
  const double edge_bound = std::min(da + ac, db + bc);
  if (cy == 0.0) return edge_bound;
  const double sx = (da * da - db * db + ab * ab) / (2.0 * ab);
  const double sy2 = da * da - sx * sx;
  if (sy2 < 0.0) return edge_bound;  // |dA - dB| > |AB|: no consistent planar source
  const double sy = -std::sqrt(sy2);
  const double cross = sx * cy - sy * cx;
  if (cross < 0.0 || cross > ab * (cy - sy)) return edge_bound;
  return std::min(edge_bound, std::sqrt((cx - sx) * (cx - sx) + (cy - sy) * (cy - sy)));
}

}  // namespace

void GeodesicOptions::check() const {
  if (!(max_distance > 0.0))
    throw std::invalid_argument("GeodesicOptions: max_distance must be > 0, got " +
                                std::to_string(max_distance));
}

std::vector<double> geodesic_distances(const mesh::TriMesh& mesh, const std::vector<int>& sources,
                                       const GeodesicOptions& options) {
  check_sources(mesh, sources, "geodesic_distances", options);
  return GeodesicSolver(mesh).distances(sources, options);
}

GeodesicSolver::GeodesicSolver(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "GeodesicSolver");
  const size_t n = mesh.vertices.size();
  const auto& p = mesh.vertices;
  start_.assign(n + 1, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++start_[t[k] + 1];
  for (size_t i = 0; i < n; ++i) start_[i + 1] += start_[i];
  wedges_.resize(start_[n]);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  double shortest = kInf, longest = 0.0;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int v = t[k], a = t[(k + 1) % 3], b = t[(k + 2) % 3];
      Wedge w{a, b, (p[a] - p[v]).norm(), (p[b] - p[v]).norm(), (p[b] - p[a]).norm(), 0, 0, 0, 0};
      // a above the edge b -> v, b above the edge v -> a (law of cosines).
      std::tie(w.cx_a, w.cy_a) = unfold(w.vb, w.ab, w.va);
      std::tie(w.cx_b, w.cy_b) = unfold(w.va, w.vb, w.ab);
      wedges_[fill[v]++] = w;
      if (w.va > 0.0) shortest = std::min(shortest, w.va), longest = std::max(longest, w.va);
    }
  dist_.assign(n, kInf);
  done_.assign(n, 0);
  // Buckets half the shortest edge wide (at most 2 x 10^4 of them): with first-in first-out
  // order inside a bucket this gave the same accuracy as an exactly ordered heap on the planar
  // grid, the icosphere and the two scans, and the same mpeg4_features points on both scans (a
  // full edge wide, Nefertiti's borderline mid-plane troughs 2.2 / 8.2 flipped).
  const double width = longest > 0.0 ? std::max(0.5 * shortest, 1e-4 * longest) : 1.0;
  queue_ = BucketQueue<int>(width, longest + width);
}

void GeodesicSolver::check_seeds(const std::vector<std::pair<int, double>>& seeds) const {
  if (seeds.empty()) throw std::invalid_argument("GeodesicSolver: no source vertex");
  for (const auto& [s, d0] : seeds) {
    if (s < 0 || s >= vertex_count())
      throw std::invalid_argument("GeodesicSolver: source vertex " + std::to_string(s) +
                                  " out of range [0, " + std::to_string(vertex_count()) + ")");
    if (!(d0 >= 0.0) || !std::isfinite(d0))
      throw std::invalid_argument("GeodesicSolver: seed distance must be finite and >= 0");
  }
}

void GeodesicSolver::march(const std::vector<std::pair<int, double>>& seeds, double max_distance) {
  order_.clear();
  queue_.clear();
  auto improve = [&](int v, double d) {
    if (dist_[v] == kInf) touched_.push_back(v);
    dist_[v] = d;
    queue_.push(d, v);
  };
  for (const auto& [s, d0] : seeds)
    if (d0 < dist_[s]) improve(s, d0);
  while (!queue_.empty()) {
    // The first pop of a vertex carries its smallest key, i.e. its current distance; later
    // (stale) entries find it done.
    const int v = queue_.pop().second;
    if (done_[v]) continue;
    const double dv = dist_[v];
    if (dv > max_distance) break;
    done_[v] = 1;
    order_.push_back(v);
    // Update each unfinished corner from v alone or from v and the other finished corner.
    for (int k = start_[v]; k < start_[v + 1]; ++k) {
      const Wedge& w = wedges_[k];
      const bool a_done = done_[w.a], b_done = done_[w.b];
      if (!a_done) {
        const double d =
            b_done ? planar_update(dist_[w.b], dv, w.vb, w.ab, w.va, w.cx_a, w.cy_a) : dv + w.va;
        if (d < dist_[w.a]) improve(w.a, d);
      }
      if (!b_done) {
        const double d =
            a_done ? planar_update(dv, dist_[w.a], w.va, w.vb, w.ab, w.cx_b, w.cy_b) : dv + w.vb;
        if (d < dist_[w.b]) improve(w.b, d);
      }
    }
  }
}

void GeodesicSolver::reset() {
  for (int v : touched_) dist_[v] = kInf, done_[v] = 0;
  touched_.clear();
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
  check_seeds(seeds);
  march(seeds, options.max_distance);
  std::vector<std::pair<int, double>> out;
  out.reserve(order_.size());
  for (int v : order_) out.emplace_back(v, dist_[v]);
  reset();
  return out;
}

std::vector<double> GeodesicSolver::distances(const std::vector<int>& sources,
                                              const GeodesicOptions& options) {
  std::vector<double> d(dist_.size(), kInf);
  for (const auto& [v, dv] : reached(sources, options)) d[v] = dv;
  return d;
}

void GeodesicSolver::distances_into(int source, float* row) {
  if (!row) throw std::invalid_argument("GeodesicSolver::distances_into: null row");
  check_seeds({{source, 0.0}});
  march({{source, 0.0}}, kInf);
  std::fill(row, row + dist_.size(), std::numeric_limits<float>::infinity());
  for (int v : order_) row[v] = float(dist_[v]);
  reset();
}

std::vector<std::vector<int>> vertex_neighbors(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "vertex_neighbors");
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

// Edge graph in compressed rows: the arcs out of v are arcs[start[v] .. start[v+1]), each with
// its Euclidean length in T (double for single-source Dijkstra, float for the matrix's vector
// sweeps); shortest / longest positive edge for Dijkstra's bucket queue.
template <class T>
struct EdgeGraph {
  struct Arc {
    int to;
    T length;
  };
  std::vector<int> start;
  std::vector<Arc> arcs;
  double shortest = kInf, longest = 0.0;
};

template <class T>
EdgeGraph<T> edge_graph(const mesh::TriMesh& mesh) {
  const auto nb = vertex_neighbors(mesh);
  EdgeGraph<T> g;
  g.start.reserve(nb.size() + 1);
  g.start.push_back(0);
  for (size_t v = 0; v < nb.size(); ++v) {
    for (int u : nb[v]) {
      const double l = (mesh.vertices[u] - mesh.vertices[v]).norm();
      g.arcs.push_back({u, T(l)});
      if (l > 0.0) g.shortest = std::min(g.shortest, l), g.longest = std::max(g.longest, l);
    }
    g.start.push_back(int(g.arcs.size()));
  }
  return g;
}

// Single-source Dijkstra over the edge graph with Dial's bucket queue (label-correcting: an
// entry whose key is above the vertex's current distance is stale and skipped). Buckets as wide
// as the shortest edge make the queue exact; a mesh whose shortest edge is below 2^-16 of its
// longest gets wider buckets, and then a vertex improved after its scan is scanned again, which
// keeps the result exact.
std::vector<double> dijkstra(const EdgeGraph<double>& g, const std::vector<int>& sources,
                             double max_distance) {
  std::vector<double> dist(g.start.size() - 1, kInf);
  const double width = g.longest > 0.0 ? std::max(g.shortest, g.longest / 65536.0) : 1.0;
  BucketQueue<int> queue(width, g.longest + width);
  for (int s : sources) {
    dist[s] = 0;
    queue.push(0.0, s);
  }
  while (!queue.empty()) {
    const auto [key, v] = queue.pop();
    const double dv = dist[v];
    if (key > float(dv)) continue;
    for (int k = g.start[v]; k < g.start[v + 1]; ++k) {
      const int u = g.arcs[k].to;
      const double d = dv + g.arcs[k].length;
      if (d < dist[u] && d <= max_distance) {
        dist[u] = d;
        queue.push(d, u);
      }
    }
  }
  return dist;
}

void check_matrix_size(const mesh::TriMesh& mesh, int max_vertices, const char* what) {
  mesh::check_mesh(mesh, what);
  if (static_cast<long long>(mesh.vertices.size()) > max_vertices)
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(mesh.vertices.size()) +
                                " vertices exceed the dense-matrix limit of " +
                                std::to_string(max_vertices) +
                                " (use single-source distances instead)");
}

// All-pairs distances over the edge graph, kLanes sources at once. Each vertex holds one
// vector of kLanes distances; Gauss-Seidel sweeps relax d(v) = min over arcs u -> v of
// d(u) + |uv| (Bellman 1958) for all lanes in one vector operation, visiting the vertices in
// x, y and z order, forward and back in turn (the sweeping of Zhao 2005, Math. Comp. 74, on a
// graph), and only vertices whose neighbour changed since their last visit. The sweeps stop when
// nothing changes: the fixpoint is the shortest-path distance Dijkstra settles (with positive
// edges it is unique; the same float sums). On a 1750-vertex sim head about 15 sweeps, a third
// of the time of one Dijkstra run per source. Rows of `sources` go to `row(source)`.
constexpr int kLanes = 32;
using Lanes = Eigen::Array<float, kLanes, 1>;

struct SweepOrders {
  std::array<std::vector<int>, 3> by_axis;  // vertex indices sorted by x, y, z
};

SweepOrders sweep_orders(const mesh::TriMesh& mesh) {
  SweepOrders o;
  const int n = static_cast<int>(mesh.vertices.size());
  for (int axis = 0; axis < 3; ++axis) {
    auto& order = o.by_axis[axis];
    order.resize(n);
    for (int v = 0; v < n; ++v) order[v] = v;
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return mesh.vertices[a][axis] < mesh.vertices[b][axis]; });
  }
  return o;
}

struct SweepScratch {
  std::vector<Lanes> dist;
  std::vector<char> dirty;
};

template <class RowOut>
void sweep_lanes(const EdgeGraph<float>& g, const SweepOrders& orders,
                 const std::array<int, kLanes>& sources, SweepScratch& w, RowOut row) {
  const int n = static_cast<int>(g.start.size()) - 1;
  w.dist.assign(n, Lanes::Constant(std::numeric_limits<float>::infinity()));
  w.dirty.assign(n, 0);
  auto mark_neighbours = [&](int v) {
    for (int k = g.start[v]; k < g.start[v + 1]; ++k) w.dirty[g.arcs[k].to] = 1;
  };
  for (int lane = 0; lane < kLanes; ++lane) {
    w.dist[sources[lane]][lane] = 0.0f;
    mark_neighbours(sources[lane]);
  }
  auto relax = [&](int v) {
    if (!w.dirty[v]) return false;
    w.dirty[v] = 0;
    Lanes d = w.dist[v];
    for (int k = g.start[v]; k < g.start[v + 1]; ++k)
      d = d.min(w.dist[g.arcs[k].to] + g.arcs[k].length);
    if (!(d < w.dist[v]).any()) return false;
    w.dist[v] = d;
    mark_neighbours(v);
    return true;
  };
  for (int sweep = 0;; ++sweep) {
    const auto& order = orders.by_axis[(sweep / 2) % 3];
    bool changed = false;
    if (sweep % 2 == 0)
      for (int i = 0; i < n; ++i) changed |= relax(order[i]);
    else
      for (int i = n - 1; i >= 0; --i) changed |= relax(order[i]);
    if (!changed) break;
  }
  for (int lane = 0; lane < kLanes; ++lane) {
    float* out = row(sources[lane]);
    for (int v = 0; v < n; ++v) out[v] = w.dist[v][lane];
  }
}

// m(i, j) = m(j, i) = the smaller of the two, in 64 x 64 tiles so the transposed reads stay in
// cache.
void symmetrize_min(DistanceMatrix& m) {
  constexpr int kTile = 64;
  float* v = m.values.data();
  const size_t n = static_cast<size_t>(m.n);
  for (size_t bi = 0; bi < n; bi += kTile)
    for (size_t bj = bi; bj < n; bj += kTile)
      for (size_t i = bi; i < std::min(bi + kTile, n); ++i)
        for (size_t j = std::max(bj, i + 1); j < std::min(bj + kTile, n); ++j) {
          const float d = std::min(v[i * n + j], v[j * n + i]);
          v[i * n + j] = v[j * n + i] = d;
        }
}

}  // namespace

std::vector<double> edge_graph_distances(const mesh::TriMesh& mesh, const std::vector<int>& sources,
                                         const GeodesicOptions& options) {
  check_sources(mesh, sources, "edge_graph_distances", options);
  return dijkstra(edge_graph<double>(mesh), sources, options.max_distance);
}

DistanceMatrix geodesic_matrix(const mesh::TriMesh& mesh, GeodesicMethod method, int max_vertices) {
  check_matrix_size(mesh, max_vertices, "geodesic_matrix");
  const int n = static_cast<int>(mesh.vertices.size());
  DistanceMatrix m{n, std::vector<float>(static_cast<size_t>(n) * n)};
  auto row = [&](int s) { return m.values.data() + static_cast<size_t>(s) * n; };
  if (method == GeodesicMethod::kEdgeGraph) {
    const auto g = edge_graph<float>(mesh);
    const SweepOrders orders = sweep_orders(mesh);
    // Sources in x order, kLanes to a block (near sources converge in the same sweeps); the
    // last block repeats its last source in the unused lanes.
    const auto& by_x = orders.by_axis[0];
    const int blocks = (n + kLanes - 1) / kLanes;
    detail::parallel_rows(
        blocks, [](int) { return SweepScratch{}; },
        [&](SweepScratch& w, int b) {
          std::array<int, kLanes> sources;
          for (int lane = 0; lane < kLanes; ++lane)
            sources[lane] = by_x[std::min(b * kLanes + lane, n - 1)];
          sweep_lanes(g, orders, sources, w, row);
        },
        detail::NoFinish{}, 2);
  } else {
    const GeodesicSolver prototype(mesh);  // copied per worker: its scratch arrays are per run
    detail::parallel_rows(
        n, [&](int) { return prototype; },
        [&](GeodesicSolver& solver, int s) { solver.distances_into(s, row(s)); });
    symmetrize_min(m);
  }
  return m;
}

DistanceMatrix euclidean_matrix(const mesh::TriMesh& mesh, int max_vertices) {
  check_matrix_size(mesh, max_vertices, "euclidean_matrix");
  const int n = static_cast<int>(mesh.vertices.size());
  DistanceMatrix m{n, std::vector<float>(static_cast<size_t>(n) * n)};
  // Coordinates as float arrays (SoA) so each row is one vectorised Eigen expression.
  Eigen::ArrayXf x(n), y(n), z(n);
  for (int i = 0; i < n; ++i)
    x[i] = float(mesh.vertices[i].x()), y[i] = float(mesh.vertices[i].y()),
    z[i] = float(mesh.vertices[i].z());
  detail::parallel_rows(
      n, [](int) { return 0; },
      [&](int, int i) {
        Eigen::Map<Eigen::ArrayXf> row(m.values.data() + static_cast<size_t>(i) * n, n);
        row = ((x - x[i]).square() + (y - y[i]).square() + (z - z[i]).square()).sqrt();
      });
  return m;
}

}  // namespace orthoface::analysis
