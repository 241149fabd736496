#include "model/evaluate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/Geometry>

namespace orthoface::model {
namespace {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection §5.1.5).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Uniform grid over the triangles for nearest-surface queries. Cells are counted from the mesh's
// bounding-box corner and are at least 1/kMaxCells of its extent, so any geometry (two tiny
// triangles a kilometre apart) gives a grid of at most kMaxCells per axis, and a query searches
// only the rings that reach the grid.
class SurfaceGrid {
 public:
  static constexpr int kMaxCells = 256;

  explicit SurfaceGrid(const mesh::TriMesh& m) : mesh_(m) {
    double mean_edge = 0;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const auto& f : m.triangles) {
      mean_edge += (m.vertices[f[1]] - m.vertices[f[0]]).norm();
      for (int v : f) lo = lo.cwiseMin(m.vertices[v]), hi = hi.cwiseMax(m.vertices[v]);
    }
    if (m.triangles.empty()) lo = hi = Eigen::Vector3d::Zero();
    origin_ = lo;
    cell_ = std::max(
        {1e-3, 2.0 * mean_edge / static_cast<double>(std::max<size_t>(1, m.triangles.size())),
         (hi - lo).maxCoeff() / (kMaxCells - 1)});
    for (size_t t = 0; t < m.triangles.size(); ++t) {
      Eigen::Vector3d tlo = m.vertices[m.triangles[t][0]], thi = tlo;
      for (int v : m.triangles[t])
        tlo = tlo.cwiseMin(m.vertices[v]), thi = thi.cwiseMax(m.vertices[v]);
      const Eigen::Vector3i a = cell_of(tlo), b = cell_of(thi);
      lo_ = lo_.cwiseMin(a), hi_ = hi_.cwiseMax(b);
      for (int x = a.x(); x <= b.x(); ++x)
        for (int y = a.y(); y <= b.y(); ++y)
          for (int z = a.z(); z <= b.z(); ++z) cells_[key(x, y, z)].push_back(static_cast<int>(t));
    }
  }

  // Signed distance: positive on the side the nearest triangle's normal points to. The rings
  // around p's cell are searched outward until no nearer triangle can remain; once that has
  // looked at more cells than hold triangles (p far from a sparse mesh), every triangle is
  // visited once instead.
  double signed_distance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3i c = cell_of(p);
    double best = std::numeric_limits<double>::infinity(), sign = 1.0;
    const int r_max = (c - lo_).cwiseAbs().cwiseMax((c - hi_).cwiseAbs()).maxCoeff();
    // Rings nearer than the grid's box hold nothing.
    const int r_min = (lo_ - c).cwiseMax(c - hi_).cwiseMax(0).maxCoeff();
    size_t looked = 0;
    const auto visit_cell = [&](int x, int y, int z) {
      ++looked;
      const auto it = cells_.find(key(x, y, z));
      if (it != cells_.end())
        for (int t : it->second) visit(p, t, best, sign);
    };
    for (int r = r_min; r <= r_max; ++r) {
      if (looked > cells_.size() + 64) {
        for (size_t t = 0; t < mesh_.triangles.size(); ++t) visit(p, int(t), best, sign);
        break;
      }
      for (int x = std::max(c.x() - r, lo_.x()); x <= std::min(c.x() + r, hi_.x()); ++x)
        for (int y = std::max(c.y() - r, lo_.y()); y <= std::min(c.y() + r, hi_.y()); ++y) {
          // Inside the shell's x-y square only the two z faces belong to this ring.
          if (std::abs(x - c.x()) == r || std::abs(y - c.y()) == r || r == 0) {
            for (int z = std::max(c.z() - r, lo_.z()); z <= std::min(c.z() + r, hi_.z()); ++z)
              visit_cell(x, y, z);
          } else {
            if (c.z() - r >= lo_.z() && c.z() - r <= hi_.z()) visit_cell(x, y, c.z() - r);
            if (c.z() + r >= lo_.z() && c.z() + r <= hi_.z()) visit_cell(x, y, c.z() + r);
          }
        }
      // Cells beyond ring r are at least r cells from p's cell (or from its projection onto the
      // clamped box, which is no farther from any of them than p).
      if (best <= r * cell_) break;
    }
    return sign * best;
  }

 private:
  void visit(const Eigen::Vector3d& p, int t, double& best, double& sign) const {
    const auto& f = mesh_.triangles[t];
    const Eigen::Vector3d &a = mesh_.vertices[f[0]], &b = mesh_.vertices[f[1]],
                          &c = mesh_.vertices[f[2]];
    const Eigen::Vector3d q = closest_on_triangle(p, a, b, c);
    const double d = (p - q).norm();
    if (d >= best) return;
    best = d;
    sign = (b - a).cross(c - a).dot(p - q) >= 0 ? 1.0 : -1.0;
  }
  // Cell of `p`, counted from the mesh's corner; far queries are clamped to a few grid widths
  // outside (their nearest cells are the same).
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = ((p - origin_) / cell_).array().floor();
    return c.cwiseMax(-4.0 * kMaxCells).cwiseMin(5.0 * kMaxCells).cast<int>();
  }
  static long long key(int x, int y, int z) {
    return ((static_cast<long long>(x) + 100000) * 200003LL + (y + 100000)) * 200003LL +
           (z + 100000);
  }
  const mesh::TriMesh& mesh_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_ = 1.0;
  Eigen::Vector3i lo_ = Eigen::Vector3i::Constant(1 << 30), hi_ = -lo_;
  std::unordered_map<long long, std::vector<int>> cells_;
};

}  // namespace

FaceRegion face_region(const std::map<std::string, Eigen::Vector3d>& l) {
  for (const char* name : {"forehead_top", "chin_bottom"})
    if (!l.count(name))
      throw std::invalid_argument(std::string("face_region: landmark '") + name + "' is missing");
  FaceRegion r;
  r.y_top = l.at("forehead_top").y();
  r.y_bottom = l.at("chin_bottom").y();
  if (!(r.y_top > r.y_bottom))
    throw std::invalid_argument("face_region: forehead_top is not above chin_bottom");
  if (l.count("ear_left_tragus") && l.count("ear_right_tragus"))
    r.z_min = 0.5 * (l.at("ear_left_tragus").z() + l.at("ear_right_tragus").z());
  return r;
}

std::vector<double> signed_distances(const std::vector<Eigen::Vector3d>& points,
                                     const mesh::TriMesh& surface) {
  mesh::check_mesh(surface, "signed_distances: surface");
  const SurfaceGrid grid(surface);
  std::vector<double> out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(grid.signed_distance(p));
  return out;
}

ErrorReport reconstruction_error(const mesh::TriMesh& rec, const mesh::TriMesh& truth,
                                 const FaceRegion& region,
                                 const std::map<std::string, Eigen::Vector3d>& landmarks,
                                 const std::map<std::string, Eigen::Vector3d>& true_landmarks) {
  mesh::check_mesh(rec, "reconstruction_error: reconstructed mesh");
  mesh::check_mesh(truth, "reconstruction_error: true mesh");
  const SurfaceGrid grid(truth);
  static const double kBary[7][3] = {{1. / 3, 1. / 3, 1. / 3},
                                     {2. / 3, 1. / 6, 1. / 6},
                                     {1. / 6, 2. / 3, 1. / 6},
                                     {1. / 6, 1. / 6, 2. / 3},
                                     {0.5, 0.5, 0},
                                     {0, 0.5, 0.5},
                                     {0.5, 0, 0.5}};
  ErrorReport e;
  double area_sum = 0, sum = 0, sum2 = 0;
  for (const auto& f : rec.triangles) {
    const Eigen::Vector3d &a = rec.vertices[f[0]], &b = rec.vertices[f[1]], &c = rec.vertices[f[2]];
    if (!region.contains((a + b + c) / 3.0)) continue;
    const double area = 0.5 * (b - a).cross(c - a).norm();
    double tri = 0, tri2 = 0;
    for (const auto& w : kBary) {
      const double d = std::abs(grid.signed_distance(w[0] * a + w[1] * b + w[2] * c));
      tri += d / 7.0, tri2 += d * d / 7.0;
      e.max_mm = std::max(e.max_mm, d);
      ++e.samples;
    }
    area_sum += area, sum += area * tri, sum2 += area * tri2;
  }
  if (e.samples == 0 || area_sum <= 0)
    throw std::invalid_argument(
        "reconstruction_error: no reconstructed triangle in the face region");
  e.mean_mm = sum / area_sum;
  e.rms_mm = std::sqrt(sum2 / area_sum);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& v : truth.vertices)
    if (region.contains(v)) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  e.diagonal_mm = (hi - lo).allFinite() && (hi - lo).minCoeff() >= 0 ? (hi - lo).norm() : 0.0;
  if (e.diagonal_mm <= 0)
    throw std::invalid_argument("reconstruction_error: no true vertex in the face region");
  e.relative = e.mean_mm / e.diagonal_mm;
  for (const auto& [name, p] : landmarks)
    if (auto it = true_landmarks.find(name); it != true_landmarks.end())
      e.landmark_mm[name] = (p - it->second).norm();
  for (const auto& [name, d] : e.landmark_mm) e.landmark_mean_mm += d / e.landmark_mm.size();
  return e;
}

mesh::TriMesh error_colored(const mesh::TriMesh& mesh, const std::vector<double>& err,
                            double range_mm) {
  if (err.size() != mesh.vertices.size())
    throw std::invalid_argument("error_colored: " + std::to_string(err.size()) + " errors for " +
                                std::to_string(mesh.vertices.size()) + " vertices");
  if (!(range_mm > 0)) throw std::invalid_argument("error_colored: range_mm must be > 0");
  mesh::TriMesh out = mesh;
  out.colors.clear();
  for (double e : err) {
    const double t = std::clamp(std::isfinite(e) ? e / range_mm : 0.0, -1.0, 1.0);
    out.colors.push_back(t >= 0 ? Eigen::Vector3d(t, 1 - t, 0) : Eigen::Vector3d(0, 1 + t, -t));
  }
  return out;
}

}  // namespace orthoface::model
