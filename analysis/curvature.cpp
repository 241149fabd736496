#include "analysis/curvature.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace orthoface::analysis {
namespace {

using Vec = Eigen::Vector3d;

// Vertex normals weighted by 1 / (|e_a|^2 |e_b|^2) per corner (Max 1999, as in trimesh2,
// which Rusinkiewicz's estimator was written against).
std::vector<Vec> vertex_normals(const mesh::TriMesh& m) {
  std::vector<Vec> n(m.vertices.size(), Vec::Zero());
  for (const auto& f : m.triangles) {
    const Vec p0 = m.vertices[f[0]], p1 = m.vertices[f[1]], p2 = m.vertices[f[2]];
    const Vec a = p0 - p1, b = p1 - p2, c = p2 - p0;
    const double la = a.squaredNorm(), lb = b.squaredNorm(), lc = c.squaredNorm();
    if (la * lb * lc <= 0.0) continue;
    const Vec fn = a.cross(b);
    n[f[0]] += fn / (la * lc);
    n[f[1]] += fn / (lb * la);
    n[f[2]] += fn / (lc * lb);
  }
  for (auto& v : n) v = v.norm() > 0.0 ? Vec(v.normalized()) : Vec::Zero();
  return n;
}

// Voronoi ("mixed") area of each corner of each triangle (Meyer et al. 2003).
std::vector<std::array<double, 3>> corner_areas(const mesh::TriMesh& m) {
  std::vector<std::array<double, 3>> ca(m.triangles.size(), {0, 0, 0});
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& f = m.triangles[i];
    const Vec e[3] = {m.vertices[f[2]] - m.vertices[f[1]], m.vertices[f[0]] - m.vertices[f[2]],
                      m.vertices[f[1]] - m.vertices[f[0]]};
    const double area = 0.5 * e[0].cross(e[1]).norm();
    if (area <= 0.0) continue;
    const double l2[3] = {e[0].squaredNorm(), e[1].squaredNorm(), e[2].squaredNorm()};
    const double ew[3] = {l2[0] * (l2[1] + l2[2] - l2[0]), l2[1] * (l2[2] + l2[0] - l2[1]),
                          l2[2] * (l2[0] + l2[1] - l2[2])};
    auto& c = ca[i];
    for (int j = 0; j < 3; ++j) {
      if (ew[j] > 0.0) continue;  // obtuse at corner j: split area as Meyer et al.
      const int a = (j + 1) % 3, b = (j + 2) % 3;
      c[a] = -0.25 * l2[b] * area / e[j].dot(e[b]);
      c[b] = -0.25 * l2[a] * area / e[j].dot(e[a]);
      c[j] = area - c[a] - c[b];
      goto next;
    }
    {
      const double s = 0.5 * area / (ew[0] + ew[1] + ew[2]);
      for (int j = 0; j < 3; ++j) c[j] = s * (ew[(j + 1) % 3] + ew[(j + 2) % 3]);
    }
  next:;
  }
  return ca;
}

// Rotates the frame (u, v) so that its normal becomes new_n (Rusinkiewicz 2004 §3).
void rotate_frame(Vec& u, Vec& v, const Vec& new_n) {
  const Vec old_n = u.cross(v);
  const double ndot = old_n.dot(new_n);
  if (ndot <= -1.0) {
    u = -u, v = -v;
    return;
  }
  const Vec perp_old = new_n - ndot * old_n;
  const Vec dperp = (old_n + new_n) / (1.0 + ndot);
  u -= dperp * u.dot(perp_old);
  v -= dperp * v.dot(perp_old);
}

// Re-expresses the tensor (ku, kuv, kv) in frame (ou, ov) in the frame (nu, nv).
Eigen::Vector3d project_tensor(const Vec& ou, const Vec& ov, const Eigen::Vector3d& k, Vec nu,
                               Vec nv) {
  rotate_frame(nu, nv, ou.cross(ov));
  const double u1 = nu.dot(ou), v1 = nu.dot(ov), u2 = nv.dot(ou), v2 = nv.dot(ov);
  return {k[0] * u1 * u1 + k[1] * 2.0 * u1 * v1 + k[2] * v1 * v1,
          k[0] * u1 * u2 + k[1] * (u1 * v2 + u2 * v1) + k[2] * v1 * v2,
          k[0] * u2 * u2 + k[1] * 2.0 * u2 * v2 + k[2] * v2 * v2};
}

// Least-squares second fundamental tensor of one face in its frame (t, b): seed 003 eq. 10.
Eigen::Vector3d face_tensor(const mesh::TriMesh& m, const std::vector<Vec>& n,
                            const std::array<int, 3>& f, const Vec& t, const Vec& b) {
  Eigen::Matrix3d w = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) {
    const int prev = (j + 2) % 3, next = (j + 1) % 3;
    const Vec e = m.vertices[f[prev]] - m.vertices[f[next]];
    const Vec dn = n[f[prev]] - n[f[next]];
    const double u = e.dot(t), v = e.dot(b), dnu = dn.dot(t), dnv = dn.dot(b);
    w(0, 0) += u * u;
    w(0, 1) += u * v;
    w(2, 2) += v * v;
    rhs += Eigen::Vector3d(dnu * u, dnu * v + dnv * u, dnv * v);
  }
  w(1, 1) = w(0, 0) + w(2, 2);
  w(1, 2) = w(0, 1);
  w(1, 0) = w(0, 1);
  w(2, 1) = w(1, 2);
  return w.ldlt().solve(rhs);
}

}  // namespace

Curvature principal_curvatures(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "principal_curvatures");
  const size_t nv = mesh.vertices.size();
  Curvature out;
  out.normals = vertex_normals(mesh);
  const auto ca = corner_areas(mesh);
  std::vector<double> point_area(nv, 0.0);
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int j = 0; j < 3; ++j) point_area[mesh.triangles[i][j]] += ca[i][j];
  // Initial vertex frames from one incident edge.
  std::vector<Vec> pu(nv, Vec::Zero()), pv(nv, Vec::Zero());
  for (const auto& f : mesh.triangles)
    for (int j = 0; j < 3; ++j) pu[f[j]] = mesh.vertices[f[(j + 1) % 3]] - mesh.vertices[f[j]];
  for (size_t i = 0; i < nv; ++i) {
    const Vec& n = out.normals[i];
    Vec u = pu[i].cross(n);
    if (u.norm() <= 0.0) u = n.unitOrthogonal();
    pu[i] = u.normalized();
    pv[i] = n.cross(pu[i]);
  }
  std::vector<Eigen::Vector3d> tensor(nv, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& f = mesh.triangles[i];
    const Vec e0 = mesh.vertices[f[2]] - mesh.vertices[f[1]];
    const Vec e1 = mesh.vertices[f[0]] - mesh.vertices[f[2]];
    const Vec fn = e0.cross(e1);
    if (fn.norm() <= 0.0 || e0.norm() <= 0.0) continue;
    const Vec t = e0.normalized(), b = fn.cross(t).normalized();
    const Eigen::Vector3d k = face_tensor(mesh, out.normals, f, t, b);
    for (int j = 0; j < 3; ++j) {
      const int v = f[j];
      if (point_area[v] <= 0.0 || out.normals[v].norm() <= 0.0) continue;
      tensor[v] += ca[i][j] / point_area[v] * project_tensor(t, b, k, pu[v], pv[v]);
    }
  }
  out.k1.resize(nv), out.k2.resize(nv), out.dir1.resize(nv), out.dir2.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    Eigen::Matrix2d m;
    m << tensor[i][0], tensor[i][1], tensor[i][1], tensor[i][2];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(m);  // ascending eigenvalues
    out.k1[i] = es.eigenvalues()[1];
    out.k2[i] = es.eigenvalues()[0];
    const Eigen::Vector2d d1 = es.eigenvectors().col(1);
    out.dir1[i] = (d1[0] * pu[i] + d1[1] * pv[i]).normalized();
    out.dir2[i] = out.normals[i].cross(out.dir1[i]);
  }
  return out;
}

double mean_curvature(double k1, double k2) { return 0.5 * (k1 + k2); }

double gaussian_curvature(double k1, double k2) { return k1 * k2; }

double shape_index(double k1, double k2) {
  if (!(k1 >= k2))
    throw std::invalid_argument("shape_index: needs k1 >= k2, got k1 = " + std::to_string(k1) +
                                ", k2 = " + std::to_string(k2));
  // atan2 with k1 - k2 >= 0 equals atan of the ratio and is defined at umbilics (eq. 13).
  return 0.5 - std::atan2(k1 + k2, k1 - k2) / M_PI;
}

double curvedness(double k1, double k2) { return std::sqrt(0.5 * (k1 * k1 + k2 * k2)); }

double ring_average(const std::vector<std::vector<int>>& neighbors,
                    const std::vector<double>& values, int vertex, double w0, double w1,
                    double w2) {
  if (neighbors.size() != values.size())
    throw std::invalid_argument("ring_average: " + std::to_string(values.size()) + " values for " +
                                std::to_string(neighbors.size()) + " vertices");
  if (vertex < 0 || vertex >= static_cast<int>(values.size()))
    throw std::invalid_argument("ring_average: vertex " + std::to_string(vertex) + " out of range");
  if (w0 < 0 || w1 < 0 || w2 < 0 || w0 + w1 + w2 <= 0)
    throw std::invalid_argument("ring_average: weights must be >= 0 and not all 0");
  // seed 003 eq. 15: weighted mean over the vertex, its 1-ring and its 2-ring.
  double sum = w0 * values[vertex], wsum = w0;
  std::vector<int> ring1 = neighbors[vertex];
  for (int u : ring1) sum += w1 * values[u], wsum += w1;
  std::vector<int> ring2;
  for (int u : ring1)
    for (int w : neighbors[u]) {
      if (w == vertex || std::find(ring1.begin(), ring1.end(), w) != ring1.end()) continue;
      if (std::find(ring2.begin(), ring2.end(), w) != ring2.end()) continue;
      ring2.push_back(w);
    }
  for (int w : ring2) sum += w2 * values[w], wsum += w2;
  return sum / wsum;
}

}  // namespace orthoface::analysis
