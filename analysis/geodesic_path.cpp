// Backtracing a geodesic through the piecewise-linear distance field (seed 003 §3 (4)).
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "analysis/geodesics.h"

namespace orthoface::analysis {
namespace {

using Vec = Eigen::Vector3d;

struct Tracer {
  const mesh::TriMesh& m;
  const std::vector<double>& d;
  std::vector<std::vector<int>> vertex_faces;
  std::map<std::pair<int, int>, std::vector<int>> edge_faces;

  Tracer(const mesh::TriMesh& mesh, const std::vector<double>& dist) : m(mesh), d(dist) {
    vertex_faces.resize(m.vertices.size());
    for (size_t f = 0; f < m.triangles.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const auto& t = m.triangles[f];
        vertex_faces[t[k]].push_back(int(f));
        edge_faces[std::minmax(t[k], t[(k + 1) % 3])].push_back(int(f));
      }
  }

  // Gradient of the linear interpolant of d over face f (zero for a degenerate face).
  Vec gradient(int f) const {
    const auto& t = m.triangles[f];
    const Vec p0 = m.vertices[t[0]], e1 = m.vertices[t[1]] - p0, e2 = m.vertices[t[2]] - p0;
    const Vec n = e1.cross(e2);
    const double a2 = n.squaredNorm();
    if (a2 <= 0.0 || !std::isfinite(d[t[0]] + d[t[1]] + d[t[2]])) return Vec::Zero();
    const double d1 = d[t[1]] - d[t[0]], d2 = d[t[2]] - d[t[0]];
    return (d1 * n.cross(e2) * -1.0 + d2 * n.cross(e1)) / a2;
  }

  // Walks from point p inside face f along direction dir to the face boundary; returns the
  // exit point as (edge vertex a, edge vertex b, weight of b) or false if dir leaves at once.
  bool exit_point(int f, const Vec& p, const Vec& dir, int skip_a, int skip_b, int& ea, int& eb,
                  double& w) const {
    const auto& t = m.triangles[f];
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      if ((a == skip_a && b == skip_b) || (a == skip_b && b == skip_a)) continue;
      // Solve p + s dir = A + u (B - A) in least squares (all in the face plane).
      const Vec ab = m.vertices[b] - m.vertices[a];
      Eigen::Matrix<double, 3, 2> M;
      M << dir, -ab;
      const Eigen::Vector2d su = M.colPivHouseholderQr().solve(m.vertices[a] - p);
      if (su[0] > 1e-12 && su[1] >= -1e-9 && su[1] <= 1 + 1e-9 && su[0] < best) {
        best = su[0], ea = a, eb = b, w = std::clamp(su[1], 0.0, 1.0);
      }
    }
    return std::isfinite(best);
  }
};

}  // namespace

GeodesicPath geodesic_path(const mesh::TriMesh& mesh, const std::vector<double>& distances,
                           int target) {
  mesh::check_mesh(mesh, "geodesic_path");
  if (distances.size() != mesh.vertices.size())
    throw std::invalid_argument("geodesic_path: " + std::to_string(distances.size()) +
                                " distances for " + std::to_string(mesh.vertices.size()) +
                                " vertices");
  if (target < 0 || target >= int(distances.size()) || !std::isfinite(distances[target]))
    throw std::invalid_argument("geodesic_path: target " + std::to_string(target) +
                                " out of range or unreached");
  const Tracer tr(mesh, distances);
  GeodesicPath path;
  path.points.push_back(mesh.vertices[target]);
  path.distances.push_back(distances[target]);
  int vertex = target, ea = -1, eb = -1;  // current position: a vertex, or a point on edge ea-eb
  int face = -1;                          // face we came through (when on an edge)
  Vec p = mesh.vertices[target];
  const size_t max_steps = 4 * (mesh.vertices.size() + mesh.triangles.size());
  for (size_t step = 0; step < max_steps; ++step) {
    if (vertex >= 0 && distances[vertex] <= 0.0) {
      path.reached_source = true;
      break;
    }
    int next_f = -1, na = -1, nb = -1;
    double w = 0.0;
    if (vertex >= 0) {
      // Steepest face around the vertex whose descent direction points into it.
      double best = 0.0;
      for (int f : tr.vertex_faces[vertex]) {
        const Vec g = tr.gradient(f);
        int a = -1, b = -1;
        double wf = 0.0;
        if (g.norm() > best && tr.exit_point(f, p, -g, vertex, vertex, a, b, wf) && a != vertex &&
            b != vertex)
          best = g.norm(), next_f = f, na = a, nb = b, w = wf;
      }
    } else {
      for (int f : tr.edge_faces.at(std::minmax(ea, eb))) {
        if (f == face) continue;
        const Vec g = tr.gradient(f);
        if (g.norm() > 0.0 && tr.exit_point(f, p, -g, ea, eb, na, nb, w)) next_f = f;
      }
    }
    Vec q;
    double dq;
    if (next_f >= 0) {
      q = (1 - w) * mesh.vertices[na] + w * mesh.vertices[nb];
      dq = (1 - w) * distances[na] + w * distances[nb];
    }
    if (next_f < 0 || !(dq < path.distances.back())) {
      // No descending face: step along an edge to the lowest neighbouring vertex.
      int low = -1;
      const std::vector<int> cand = vertex >= 0 ? std::vector<int>{} : std::vector<int>{ea, eb};
      std::vector<int> around = cand;
      if (vertex >= 0)
        for (int f : tr.vertex_faces[vertex])
          for (int k : mesh.triangles[f]) around.push_back(k);
      for (int u : around)
        if (distances[u] < path.distances.back() && (low < 0 || distances[u] < distances[low]))
          low = u;
      if (low < 0) break;  // flat or local minimum that is not a source
      vertex = low, ea = eb = face = -1, p = mesh.vertices[low];
      path.points.push_back(p), path.distances.push_back(distances[low]);
      continue;
    }
    p = q, face = next_f;
    if (w <= 1e-9 || w >= 1 - 1e-9) {
      vertex = w <= 1e-9 ? na : nb, ea = eb = -1, p = mesh.vertices[vertex];
      dq = distances[vertex];
    } else {
      vertex = -1, ea = na, eb = nb;
    }
    path.points.push_back(p), path.distances.push_back(dq);
  }
  return path;
}

}  // namespace orthoface::analysis
