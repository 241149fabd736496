// make_head: the (u, t) grid mesh of the analytic head surface and its landmarks.
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

#include "sim/head.h"
#include "sim/head_surface.h"

namespace orthoface::sim {

namespace detail {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kWarp = 0.6;  // 0: uniform around; 0.6: face columns 2.5x denser than average
}  // namespace

double HeadParametrization::theta(double u) {
  return kPi * (2 * u - 1) + kWarp * std::sin(2 * kPi * u);
}

double HeadParametrization::u_of_theta(double th) {
  double lo = 0, hi = 1;  // theta(u) is increasing (kWarp < 1)
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (theta(mid) < th ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

HeadParametrization::HeadParametrization(const HeadSurface& s) {
  const HeadAnchors& a = s.anchors();
  constexpr int kSamples = 2400;
  const double thetas[] = {0.0, 0.25, 0.5, 0.9, 1.3, kPi / 2, 1.9, 2.5, kPi};
  std::vector<double> prev;
  double acc = 0;
  for (int i = 0; i <= kSamples; ++i) {
    const double y = a.y_top + (a.y_bottom - a.y_top) * i / kSamples;
    std::vector<double> r;
    for (double th : thetas) r.push_back(s.radius(th, y));
    if (i > 0) {
      double dr = 0;
      for (size_t k = 0; k < r.size(); ++k) dr = std::max(dr, std::abs(r[k] - prev[k]));
      const double dy = (a.y_top - a.y_bottom) / kSamples;
      // Face heights get about twice the ring density of the skull and the neck.
      const double face = smoothstep(a.y_menton - 20, a.y_menton - 5, y) *
                          (1 - smoothstep(a.y_brow + 5, a.y_hair + 5, y));
      // Steep steps (under the nose) get somewhat denser rings, but capped: rings are global,
      // so a cluster there would crowd the whole circumference.
      acc += (1 + 1.3 * face) * std::hypot(dy, y < a.y_brow ? std::min(dr, 1.2 * dy) : dr);
    }
    ys_.push_back(y);
    ts_.push_back(acc);
    prev = r;
  }
  for (double& t : ts_) t /= acc;
}

double HeadParametrization::y(double t) const {
  const auto it = std::lower_bound(ts_.begin(), ts_.end(), t);
  if (it == ts_.begin()) return ys_.front();
  if (it == ts_.end()) return ys_.back();
  const size_t k = it - ts_.begin();
  const double f = (t - ts_[k - 1]) / std::max(1e-15, ts_[k] - ts_[k - 1]);
  return ys_[k - 1] + f * (ys_[k] - ys_[k - 1]);
}

double HeadParametrization::t_of_y(double yy) const {
  // ys_ descends: find the first sample below yy.
  const auto it = std::lower_bound(ys_.begin(), ys_.end(), yy, std::greater<double>());
  if (it == ys_.begin()) return 0;
  if (it == ys_.end()) return 1;
  const size_t k = it - ys_.begin();
  const double f = (yy - ys_[k - 1]) / (ys_[k] - ys_[k - 1]);
  return ts_[k - 1] + f * (ts_[k] - ts_[k - 1]);
}

}  // namespace detail

namespace {

using detail::HeadParametrization;
using detail::HeadSurface;
using detail::kPi;

// The grid: rings (t values, crown pole excluded, last = bottom of the neck) x segments.
struct Grid {
  int segments = 0;
  std::vector<double> ring_t;  // ascending, ring_t.back() == 1
};

// Ring t values: uniform in t, then warped piecewise linearly so that a ring lies on each key
// height (profile landmarks such as the nose tip, lips and chin become mesh vertices) while the
// spacing changes gradually.
Grid make_grid(const HeadOptions& o, const HeadParametrization& param,
               const std::vector<double>& key_y) {
  Grid g;
  int rings = o.rings;
  g.segments = o.segments;
  if (rings <= 0) {
    g.segments =
        std::max(16, 2 * static_cast<int>(std::lround(std::sqrt(0.6 * o.target_triangles) / 2)));
    rings =
        std::max(16, static_cast<int>(std::lround(o.target_triangles / (2.0 * g.segments))) - 1);
  }
  std::map<int, double> anchor = {{0, 0.0}, {rings, 1.0}};  // ring number (1-based) -> t
  for (double y : key_y) {
    const double t = param.t_of_y(y);
    const int k = static_cast<int>(std::lround(t * rings));
    if (k > 0 && k < rings && !anchor.count(k)) anchor[k] = t;
  }
  // Drop anchors that would not keep t increasing.
  for (auto it = std::next(anchor.begin()); it != anchor.end();) {
    if (it->second <= std::prev(it)->second)
      it = anchor.erase(it);
    else
      ++it;
  }
  for (int k = 1; k <= rings; ++k) {
    const auto hi = anchor.lower_bound(k);  // exists: anchor[rings]
    if (hi->first == k) {
      g.ring_t.push_back(hi->second);
      continue;
    }
    const auto lo = std::prev(hi);  // exists: anchor[0]
    const double f = static_cast<double>(k - lo->first) / (hi->first - lo->first);
    g.ring_t.push_back(lo->second + f * (hi->second - lo->second));
  }
  return g;
}

// Vertex index of ring i (0-based), column j (0..segments; column `segments` is the seam copy
// of column 0). Vertex 0 is the crown; the cap ring and the bottom pole come last.
int vid(const Grid& g, int i, int j) { return 1 + i * (g.segments + 1) + j; }

mesh::TriMesh grid_mesh(const HeadSurface& s, const HeadParametrization& param, const Grid& g) {
  const int n = g.segments, rings = static_cast<int>(g.ring_t.size());
  const bool mirror = s.params().asymmetry == 0;
  mesh::TriMesh m;
  const auto& a = s.anchors();
  m.vertices.push_back({0, a.y_top, 0});
  m.uvs.push_back({0.5, 1.0});
  for (int i = 0; i <= rings; ++i) {  // ring `rings` is the cap ring inside the bottom ring
    const bool cap = i == rings;
    const double t = cap ? 1.0 : g.ring_t[i], y = param.y(t);
    const size_t first = m.vertices.size();
    for (int j = 0; j <= n; ++j) {
      const double u = static_cast<double>(j) / n;
      Eigen::Vector3d p;
      if (j == n) {
        p = m.vertices[first];
      } else if (mirror && 2 * j > n) {
        p = m.vertices[first + (n - j)];
        p.x() = -p.x();
      } else {
        p = s.point(HeadParametrization::theta(u), y);
        if (cap) p = Eigen::Vector3d(0.5 * p.x(), p.y(), 0.5 * p.z());
      }
      m.vertices.push_back(p);
      m.uvs.push_back({u, 1.0 - t});
    }
  }
  m.vertices.push_back({0, param.y(1.0), 0});
  m.uvs.push_back({0.5, 0.0});
  const int bottom = static_cast<int>(m.vertices.size()) - 1;
  for (int j = 0; j < n; ++j) m.triangles.push_back({0, vid(g, 0, j), vid(g, 0, j + 1)});
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < n; ++j) {
      const int A = vid(g, i, j), B = vid(g, i, j + 1), C = vid(g, i + 1, j + 1),
                D = vid(g, i + 1, j);
      if (2 * j < n) {  // diagonals mirror across the midline, so the mesh is symmetric
        m.triangles.push_back({A, D, C});
        m.triangles.push_back({A, C, B});
      } else {
        m.triangles.push_back({A, D, B});
        m.triangles.push_back({B, D, C});
      }
    }
  for (int j = 0; j < n; ++j)
    m.triangles.push_back({bottom, vid(g, rings, j + 1), vid(g, rings, j)});
  return m;
}

// The mesh point with parameters (u, t): barycentric inside the grid triangle holding (u, t),
// so it lies on the mesh exactly where the texture shows texel (u, t).
Eigen::Vector3d mesh_point(const Grid& g, const mesh::TriMesh& m, double u, double t) {
  const int n = g.segments;
  const int j = std::clamp(static_cast<int>(u * n), 0, n - 1);
  const double fu = u * n - j;
  const auto it = std::lower_bound(g.ring_t.begin(), g.ring_t.end(), t);
  const int i1 = static_cast<int>(it - g.ring_t.begin());  // ring at or below t
  const Eigen::Vector3d& V = m.vertices[0];
  if (i1 == 0) {  // crown fan
    const double f = t / g.ring_t[0];
    const Eigen::Vector3d q =
        (1 - fu) * m.vertices[vid(g, 0, j)] + fu * m.vertices[vid(g, 0, j + 1)];
    return V + f * (q - V);
  }
  const int i = i1 - 1;
  const double ft = (t - g.ring_t[i]) / (g.ring_t[i1] - g.ring_t[i]);
  const Eigen::Vector3d &A = m.vertices[vid(g, i, j)], &B = m.vertices[vid(g, i, j + 1)],
                        &C = m.vertices[vid(g, i1, j + 1)], &D = m.vertices[vid(g, i1, j)];
  if (2 * j < n) {
    if (ft >= fu) return A * (1 - ft) + D * (ft - fu) + C * fu;
    return A * (1 - fu) + C * ft + B * (fu - ft);
  }
  if (fu + ft <= 1) return A * (1 - fu - ft) + D * ft + B * fu;
  return B * (1 - ft) + D * (1 - fu) + C * (fu + ft - 1);
}

}  // namespace

Head make_head(const HeadParams& params, const HeadOptions& options) {
  params.check();
  options.check();
  const HeadSurface surface(params);
  const HeadParametrization param(surface);
  const detail::LandmarkParams lp = detail::landmark_params(surface, param);
  const Grid grid = make_grid(options, param, lp.key_y);
  Head head;
  head.mesh = grid_mesh(surface, param, grid);
  head.mesh.texture = detail::head_texture(surface, param, options.texture_size);
  for (const auto& [name, ut] : lp.ut)
    head.landmarks[name] = mesh_point(grid, head.mesh, ut.x(), ut.y());
  mesh::check_mesh(head.mesh, "make_head");
  return head;
}

Head make_head(int seed) {
  Head head = make_head(head_params(seed));
  head.name = "sim seed " + std::to_string(seed);
  return head;
}

}  // namespace orthoface::sim
