#include "analysis/analysis_mesh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "mesh/topology.h"

namespace orthoface::analysis {
namespace {

int find_root(std::vector<int>& parent, int v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// Welded index per vertex: vertices in the same grid cell (or a neighbouring one) within tol.
std::vector<int> weld_map(const std::vector<Eigen::Vector3d>& p, double tol) {
  std::vector<int> map(p.size());
  std::iota(map.begin(), map.end(), 0);
  if (tol <= 0.0) return map;
  std::map<std::tuple<long, long, long>, std::vector<int>> grid;
  for (size_t i = 0; i < p.size(); ++i) {
    const long cx = std::lround(p[i].x() / tol), cy = std::lround(p[i].y() / tol),
               cz = std::lround(p[i].z() / tol);
    int found = -1;
    for (long dx = -1; dx <= 1 && found < 0; ++dx)
      for (long dy = -1; dy <= 1 && found < 0; ++dy)
        for (long dz = -1; dz <= 1 && found < 0; ++dz) {
          auto it = grid.find({cx + dx, cy + dy, cz + dz});
          if (it == grid.end()) continue;
          for (int j : it->second)
            if ((p[j] - p[i]).norm() <= tol) {
              found = j;
              break;
            }
        }
    if (found >= 0) {
      map[i] = found;
    } else {
      grid[{cx, cy, cz}].push_back(int(i));
    }
  }
  return map;
}

}  // namespace

std::vector<int> component_labels(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "component_labels");
  const int n = int(mesh.vertices.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<char> used(n, 0);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      used[t[k]] = 1;
      parent[find_root(parent, t[k])] = find_root(parent, t[(k + 1) % 3]);
    }
  std::map<int, int> size;
  for (int v = 0; v < n; ++v)
    if (used[v]) ++size[find_root(parent, v)];
  std::vector<std::pair<int, int>> order;  // (-size, root)
  for (const auto& [root, s] : size) order.emplace_back(-s, root);
  std::sort(order.begin(), order.end());
  std::map<int, int> rank;
  for (size_t i = 0; i < order.size(); ++i) rank[order[i].second] = int(i);
  std::vector<int> label(n, -1);
  for (int v = 0; v < n; ++v)
    if (used[v]) label[v] = rank[find_root(parent, v)];
  return label;
}

AnalysisMesh analysis_mesh(const mesh::TriMesh& mesh, const std::string& what,
                           bool keep_largest_component, double weld_tolerance) {
  mesh::check_mesh(mesh, what);
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  const double diag = box.diagonal().norm();
  const std::vector<int> weld = weld_map(mesh.vertices, weld_tolerance * diag);
  AnalysisMesh out;
  mesh::TriMesh welded;
  welded.vertices = mesh.vertices;
  for (const auto& t : mesh.triangles) {
    const std::array<int, 3> w = {weld[t[0]], weld[t[1]], weld[t[2]]};
    const bool repeated = w[0] == w[1] || w[1] == w[2] || w[0] == w[2];
    if (repeated || (mesh.vertices[w[1]] - mesh.vertices[w[0]])
                            .cross(mesh.vertices[w[2]] - mesh.vertices[w[0]])
                            .norm() <= 1e-12 * diag * diag) {
      ++out.dropped_triangles;
      continue;
    }
    welded.triangles.push_back(w);
  }
  if (welded.triangles.empty())
    throw std::invalid_argument(what + ": no triangle with a non-zero area");
  for (size_t i = 0; i < weld.size(); ++i) out.welded += weld[i] != int(i);
  const std::vector<int> comp = component_labels(welded);
  out.components = *std::max_element(comp.begin(), comp.end()) + 1;
  // Keep the vertices of the kept triangles, renumbered in input order.
  out.analysis_index.assign(mesh.vertices.size(), -1);
  for (const auto& t : welded.triangles) {
    if (keep_largest_component && comp[t[0]] != 0) continue;
    for (int v : t)
      if (out.analysis_index[v] < 0) out.analysis_index[v] = 0;
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    if (out.analysis_index[v] >= 0) {
      out.analysis_index[v] = int(out.original_index.size());
      out.original_index.push_back(int(v));
      out.mesh.vertices.push_back(mesh.vertices[v]);
    }
  for (const auto& t : welded.triangles)
    if (!keep_largest_component || comp[t[0]] == 0)
      out.mesh.triangles.push_back(
          {out.analysis_index[t[0]], out.analysis_index[t[1]], out.analysis_index[t[2]]});
  for (size_t v = 0; v < weld.size(); ++v) out.analysis_index[v] = out.analysis_index[weld[v]];
  if (out.welded > 0)
    out.warnings.push_back(std::to_string(out.welded) + " coincident vertices welded");
  if (out.dropped_triangles > 0)
    out.warnings.push_back(std::to_string(out.dropped_triangles) + " degenerate triangles dropped");
  if (out.components > 1)
    out.warnings.push_back(std::to_string(out.components) + " connected components" +
                           (keep_largest_component ? ": only the largest is analysed" : ""));
  const mesh::TopologyReport topo = mesh::topology_report(out.mesh);
  if (!topo.manifold())
    out.warnings.push_back(
        "not a manifold: " + std::to_string(topo.non_manifold_edges) +
        " edge(s) shared by more than two triangles, " +
        std::to_string(topo.non_manifold_vertices) +
        " vertex(es) joining separate fans; analysed as they are (geodesics and curvatures may "
        "be off there)");
  return out;
}

}  // namespace orthoface::analysis
