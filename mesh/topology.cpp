// Topology checks by hand on a plain edge map: OpenMesh's halfedge structure cannot hold the
// non-manifold input these checks exist to report (add_face refuses complex edges).
#include "mesh/topology.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>

namespace orthoface::mesh {

namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root is the lowest index
  }
};

double bbox_diagonal(const std::vector<Eigen::Vector3d>& v) {
  if (v.empty()) return 0;
  Eigen::Vector3d lo = v[0], hi = v[0];
  for (const auto& p : v) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).norm();
}

std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
         static_cast<std::uint32_t>(std::max(a, b));
}

// Vertices whose triangles form more than one fan (joined only through the vertex itself).
int count_non_manifold_vertices(const std::vector<std::array<int, 3>>& tris,
                                const std::unordered_map<std::uint64_t, std::pair<int, int>>& edges,
                                size_t num_vertices) {
  std::vector<std::vector<int>> around(num_vertices);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int v : tris[t]) around[v].push_back(static_cast<int>(t));
  int count = 0;
  for (size_t v = 0; v < num_vertices; ++v) {
    const auto& ts = around[v];
    if (ts.size() < 2) continue;
    UnionFind uf(static_cast<int>(ts.size()));
    std::map<int, std::vector<int>> by_other;  // other end of an edge at v -> local triangles
    for (size_t k = 0; k < ts.size(); ++k)
      for (int w : tris[ts[k]])
        if (w != static_cast<int>(v)) by_other[w].push_back(static_cast<int>(k));
    for (const auto& [w, ks] : by_other)
      if (ks.size() == 2 && edges.at(edge_key(static_cast<int>(v), w)).first == 2)
        uf.unite(ks[0], ks[1]);
    int fans = 0;
    for (size_t k = 0; k < ts.size(); ++k)
      fans += uf.find(static_cast<int>(k)) == static_cast<int>(k);
    if (fans > 1) ++count;
  }
  return count;
}

}  // namespace

void TopologyOptions::check() const {
  if (!std::isfinite(weld_tolerance) || weld_tolerance < 0)
    throw std::invalid_argument("TopologyOptions: weld_tolerance must be >= 0, got " +
                                std::to_string(weld_tolerance));
}

std::vector<int> weld_map(const TriMesh& mesh, const TopologyOptions& options) {
  options.check();
  const auto& v = mesh.vertices;
  for (size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite())
      throw std::invalid_argument("weld_map: vertex " + std::to_string(i) + " is not finite");
  const int n = static_cast<int>(v.size());
  UnionFind uf(n);
  const double tol = options.weld_tolerance * bbox_diagonal(v);
  // Hash grid with cells of size tol (exact positions when tol is 0): neighbours of a vertex are
  // in its own and the 26 surrounding cells.
  const double cell = tol > 0 ? tol : 1.0;
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (x * 73856093) ^ (y * 19349663) ^ (z * 83492791);
  };
  std::unordered_map<std::int64_t, std::vector<int>> grid;
  for (int i = 0; i < n; ++i) {
    const std::int64_t cx = static_cast<std::int64_t>(std::floor(v[i].x() / cell)),
                       cy = static_cast<std::int64_t>(std::floor(v[i].y() / cell)),
                       cz = static_cast<std::int64_t>(std::floor(v[i].z() / cell));
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(cx + dx, cy + dy, cz + dz));
          if (it == grid.end()) continue;
          for (int j : it->second)
            if ((v[i] - v[j]).norm() <= tol) uf.unite(i, j);
        }
    grid[key(cx, cy, cz)].push_back(i);
  }
  std::vector<int> rep(n);
  for (int i = 0; i < n; ++i) rep[i] = uf.find(i);
  return rep;
}

TriMesh weld(const TriMesh& mesh, const TopologyOptions& options) {
  check_mesh(mesh, "weld");
  const std::vector<int> rep = weld_map(mesh, options);
  std::vector<int> index(rep.size(), -1);
  TriMesh out;
  out.texture = mesh.texture;
  for (size_t i = 0; i < rep.size(); ++i) {
    if (rep[i] != static_cast<int>(i)) continue;
    index[i] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(mesh.vertices[i]);
    if (!mesh.uvs.empty()) out.uvs.push_back(mesh.uvs[i]);
    if (!mesh.colors.empty()) out.colors.push_back(mesh.colors[i]);
  }
  for (const auto& t : mesh.triangles) {
    const std::array<int, 3> w = {index[rep[t[0]]], index[rep[t[1]]], index[rep[t[2]]]};
    if (w[0] != w[1] && w[1] != w[2] && w[0] != w[2]) out.triangles.push_back(w);
  }
  return out;
}

TopologyReport topology_report(const TriMesh& mesh, const TopologyOptions& options) {
  check_mesh(mesh, "topology_report");
  const std::vector<int> rep = weld_map(mesh, options);
  TopologyReport r;
  r.input_vertices = static_cast<int>(mesh.vertices.size());
  const double diag = bbox_diagonal(mesh.vertices);
  const double min_area2 = std::pow(1e-12 * diag * diag, 2);  // |cross|^2 below: zero area
  std::vector<std::array<int, 3>> tris;
  for (const auto& t : mesh.triangles) {
    const std::array<int, 3> w = {rep[t[0]], rep[t[1]], rep[t[2]]};
    const Eigen::Vector3d c = (mesh.vertices[w[1]] - mesh.vertices[w[0]])
                                  .cross(mesh.vertices[w[2]] - mesh.vertices[w[0]]);
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2] || c.squaredNorm() <= min_area2)
      ++r.degenerate_triangles;
    else
      tris.push_back(w);
  }
  r.triangles = static_cast<int>(tris.size());
  // Edges: triangle count and direction balance (+1 for a->b with a < b, -1 otherwise).
  std::unordered_map<std::uint64_t, std::pair<int, int>> edges;
  std::vector<char> used(mesh.vertices.size(), 0);
  UnionFind comp(static_cast<int>(mesh.vertices.size()));
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      auto& e = edges[edge_key(a, b)];
      ++e.first;
      e.second += a < b ? 1 : -1;
      used[a] = 1;
      comp.unite(a, b);
    }
  r.edges = static_cast<int>(edges.size());
  for (const auto& [k, e] : edges) {
    if (e.first == 1) ++r.boundary_edges;
    if (e.first > 2) ++r.non_manifold_edges;
    if (e.first == 2 && e.second != 0) ++r.inconsistent_edges;
  }
  for (size_t i = 0; i < rep.size(); ++i) {
    if (rep[i] != static_cast<int>(i)) continue;
    if (!used[i])
      ++r.isolated_vertices;
    else {
      ++r.vertices;
      if (comp.find(static_cast<int>(i)) == static_cast<int>(i)) ++r.components;
    }
  }
  r.non_manifold_vertices = count_non_manifold_vertices(tris, edges, mesh.vertices.size());
  r.euler_characteristic = r.vertices - r.edges + r.triangles;
  return r;
}

}  // namespace orthoface::mesh
