// Seed 000: key vertices (both ears, their midpoint, the nose tip), local axes, symmetry plane and
// MPEG-4 feature points of a head mesh, independent of its pose and scale.
#include "model/mpeg4_features.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <tuple>

#include "model/analysis_mesh.h"
#include "model/feature_detail.h"
#include "model/geodesics.h"
#include "model/mpeg4_names.h"

namespace orthoface::model {
namespace {

using detail::LocalFrame;

struct Cluster {
  std::vector<int> vertices;
  double mass = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

std::vector<double> vertex_areas(const TriMesh& m) {
  std::vector<double> a(m.vertices.size(), 0.0);
  for (const auto& t : m.triangles) {
    const double area = 0.5 * (m.vertices[t[1]] - m.vertices[t[0]])
                                  .cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
    for (int v : t) a[v] += area / 3.0;
  }
  return a;
}

// Groups of vertices with ratio >= t joined when closer than `gap` (z_clusters), heaviest
// first; mass = sum of (ratio - 1) x vertex area. The gap lets one ear stay one cluster when its
// dense rim is broken.
std::vector<Cluster> dense_clusters(const TriMesh& m, const std::vector<double>& ratio, double t,
                                    double gap) {
  const auto area = vertex_areas(m);
  std::map<std::tuple<long, long, long>, std::vector<int>> grid;
  auto key = [&](const Eigen::Vector3d& p) {
    return std::make_tuple(long(std::floor(p.x() / gap)), long(std::floor(p.y() / gap)),
                           long(std::floor(p.z() / gap)));
  };
  for (size_t v = 0; v < m.vertices.size(); ++v)
    if (ratio[v] >= t) grid[key(m.vertices[v])].push_back(int(v));
  std::vector<int> seen(m.vertices.size(), 0);
  std::vector<Cluster> out;
  for (size_t s = 0; s < m.vertices.size(); ++s) {
    if (seen[s] || ratio[s] < t) continue;
    Cluster c;
    std::vector<int> stack{int(s)};
    seen[s] = 1;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      c.vertices.push_back(v);
      const double w = (ratio[v] - 1.0) * area[v];
      c.mass += w, c.centroid += w * m.vertices[v];
      const auto [kx, ky, kz] = key(m.vertices[v]);
      for (long dx = -1; dx <= 1; ++dx)
        for (long dy = -1; dy <= 1; ++dy)
          for (long dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find({kx + dx, ky + dy, kz + dz});
            if (it == grid.end()) continue;
            for (int u : it->second)
              if (!seen[u] && (m.vertices[u] - m.vertices[v]).norm() <= gap)
                seen[u] = 1, stack.push_back(u);
          }
    }
    if (c.mass > 0.0) c.centroid /= c.mass;
    out.push_back(std::move(c));
  }
  std::sort(out.begin(), out.end(), [](const Cluster& a, const Cluster& b) { return a.mass > b.mass; });
  return out;
}

int nearest_vertex(const TriMesh& m, const std::vector<int>& among, const Eigen::Vector3d& p) {
  int best = among.front();
  for (int v : among)
    if ((m.vertices[v] - p).squaredNorm() < (m.vertices[best] - p).squaredNorm()) best = v;
  return best;
}

// Mean point-to-tangent-plane distance from mirrored sample vertices to the nearest vertex,
// / d (seed 000: the face is symmetric). The tangent plane removes the vertex-spacing floor.
double mirror_error(const TriMesh& m, const std::vector<Eigen::Vector3d>& normals,
                    const Eigen::Vector3d& n, const Eigen::Vector3d& o, double d) {
  const double cell = 0.04 * d;
  std::map<std::tuple<long, long, long>, std::vector<int>> grid;
  auto key = [&](const Eigen::Vector3d& p) {
    return std::make_tuple(long(std::floor(p.x() / cell)), long(std::floor(p.y() / cell)),
                           long(std::floor(p.z() / cell)));
  };
  for (size_t v = 0; v < m.vertices.size(); ++v) grid[key(m.vertices[v])].push_back(int(v));
  const size_t step = std::max<size_t>(1, m.vertices.size() / 400);
  double sum = 0.0;
  int count = 0;
  for (size_t v = 0; v < m.vertices.size(); v += step) {
    const Eigen::Vector3d p = m.vertices[v], q = p - 2.0 * n.dot(p - o) * n;
    double best = cell;  // capped: farther than one cell counts as one cell
    int at = -1;
    const auto [kx, ky, kz] = key(q);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find({kx + dx, ky + dy, kz + dz});
          if (it == grid.end()) continue;
          for (int u : it->second)
            if ((m.vertices[u] - q).norm() < best) best = (m.vertices[u] - q).norm(), at = u;
        }
    if (at >= 0) best = std::abs(normals[at].dot(q - m.vertices[at]));
    sum += best, ++count;
  }
  return sum / count / d;
}

std::vector<Eigen::Vector3d> area_normals(const TriMesh& m) {
  std::vector<Eigen::Vector3d> n(m.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d fn =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    for (int v : t) n[v] += fn;
  }
  for (auto& x : n) x = x.norm() > 0 ? Eigen::Vector3d(x.normalized()) : Eigen::Vector3d::Zero();
  return n;
}

// The ear pair (seed 000 §VI.G): two heavy, similar clusters far apart whose bisecting plane
// is a mirror plane of the mesh.
std::optional<std::pair<int, int>> ear_pair(const TriMesh& m, const std::vector<Cluster>& cl,
                                            double diag, double& sym_error) {
  struct Cand { double score; int a, b; };
  std::vector<Cand> cands;
  const size_t top = std::min<size_t>(cl.size(), 15);
  for (size_t a = 0; a < top; ++a)
    for (size_t b = a + 1; b < top; ++b) {
      const double lo = std::min(cl[a].mass, cl[b].mass), hi = std::max(cl[a].mass, cl[b].mass);
      const double d = (cl[a].centroid - cl[b].centroid).norm();
      if (lo < 0.25 * hi || lo < 0.02 * cl[0].mass || d < 0.15 * diag) continue;
      cands.push_back({d * std::sqrt(lo), int(a), int(b)});
    }
  std::sort(cands.begin(), cands.end(), [](const Cand& x, const Cand& y) { return x.score > y.score; });
  std::optional<std::pair<int, int>> best;
  sym_error = 1.0;
  const auto normals = area_normals(m);
  for (size_t k = 0; k < cands.size() && k < 8; ++k) {
    const Eigen::Vector3d pa = cl[cands[k].a].centroid, pb = cl[cands[k].b].centroid;
    const double d = (pb - pa).norm();
    const double e = mirror_error(m, normals, (pb - pa) / d, 0.5 * (pa + pb), d);
    if (e < 0.02 && e < sym_error) sym_error = e, best = std::make_pair(cands[k].a, cands[k].b);
  }
  return best;
}

// Forward direction: from P3 to the heaviest cluster on the bisecting plane (eyes, nose, lips).
std::optional<Eigen::Vector3d> face_direction(const std::vector<Cluster>& cl, int ea, int eb,
                                              const LocalFrame& fr) {
  for (size_t c = 0; c < cl.size(); ++c) {
    if (int(c) == ea || int(c) == eb) continue;
    const Eigen::Vector3d q = cl[c].centroid - fr.origin;
    if (std::abs(q.dot(fr.left)) > 0.15 * fr.ear_distance || q.norm() < 0.3 * fr.ear_distance)
      continue;
    const Eigen::Vector3d f = q - q.dot(fr.left) * fr.left;
    if (f.norm() > 0.0) return f.normalized();
  }
  return std::nullopt;
}

// Seed 000 §VI.H line Delta: the line touching the mid-plane profile above and below the nose
// (brow and chin side). Up becomes Delta's direction and forward its normal toward the nose,
// so peaks and troughs are measured from the face line rather than from the tilted ear-nose axis.
void face_line_frame(const TriMesh& m, const FeatureOptions& o, LocalFrame& fr, int nose) {
  const auto prof = detail::plane_profile(m, fr, 0.0, o.plane_band * fr.ear_distance);
  const Eigen::Vector3d q = m.vertices[nose] - fr.origin;
  const double st = q.dot(fr.up), ft = q.dot(fr.forward), reach = 0.7 * fr.ear_distance;
  const detail::ProfileSample* above = nullptr;
  const detail::ProfileSample* below = nullptr;
  double best_a = 1e300, best_b = 1e300;
  for (const auto& p : prof) {
    const double ds = p.s - st;
    if (std::abs(ds) < 0.05 * fr.ear_distance || std::abs(ds) > reach) continue;
    const double slope = (ft - p.f) / std::abs(ds);  // smallest: the tangent from the tip
    if (ds > 0 && slope < best_a) best_a = slope, above = &p;
    if (ds < 0 && slope < best_b) best_b = slope, below = &p;
  }
  if (!above || !below) return;  // keep the ear-nose frame
  const Eigen::Vector3d up = ((above->s - below->s) * fr.up + (above->f - below->f) * fr.forward)
                                 .normalized();
  fr.up = up;
  fr.forward = fr.left.cross(up);
}

// Index of the mid-plane vertex that stands out most in front of both of its sides: f minus the
// larger of the profile maxima 0.12-0.35 D above and below it (the nose beats the chin, whose
// upper side holds the lips). -1 for an empty profile.
int most_protruding(const TriMesh& m, const FeatureOptions& o, const LocalFrame& fr) {
  const auto prof = detail::plane_profile(m, fr, 0.0, o.plane_band * fr.ear_distance);
  const double near = 0.12 * fr.ear_distance, far = 0.35 * fr.ear_distance;
  int best = -1;
  double best_h = -1e300;
  for (const auto& c : prof) {
    // Face points lie within ~0.85 D of the ear midpoint; a neck cut or a bust base is farther.
    if ((m.vertices[c.vertex] - fr.origin).norm() > 0.95 * fr.ear_distance) continue;
    double above = -1e300, below = -1e300;
    for (const auto& p : prof) {
      const double ds = p.s - c.s;
      if (std::abs(ds) < near || std::abs(ds) > far) continue;
      (ds > 0 ? above : below) = std::max(ds > 0 ? above : below, p.f);
    }
    if (above < -1e299 || below < -1e299) continue;
    const double h = c.f - std::max(above, below);
    if (h > best_h) best_h = h, best = c.vertex;
  }
  return best;
}

// Builds the frame and the key vertices; returns false (with report.missing) when it cannot.
bool key_vertices(const TriMesh& m, const std::vector<double>& ratio, const FeatureOptions& o,
                  FeatureReport& r, LocalFrame& fr, std::vector<Cluster>& cl, int& ea, int& eb) {
  const double diag = pose_free_size(m);
  std::vector<double> sorted = ratio;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() * 95 / 100, sorted.end());
  const double t = std::clamp(sorted[sorted.size() * 95 / 100], 1.08, o.ratio_threshold);
  cl = dense_clusters(m, ratio, t, 0.5 * o.neighbourhood * diag);
  r.cluster.assign(m.vertices.size(), -1);
  for (size_t c = 0; c < cl.size(); ++c)
    for (int v : cl[c].vertices) r.cluster[v] = int(c);
  const auto pair = ear_pair(m, cl, diag, r.symmetry_error);
  if (!pair) {
    r.missing.push_back("ears (P1, P2): no symmetric pair of dense clusters (" +
                        std::to_string(cl.size()) + " clusters); a face without ears cannot "
                        "give the ears, their midpoint, the axes or the points that need them");
    return false;
  }
  std::tie(ea, eb) = *pair;
  const int va = nearest_vertex(m, cl[ea].vertices, cl[ea].centroid);
  const int vb = nearest_vertex(m, cl[eb].vertices, cl[eb].centroid);
  fr.ear_distance = (m.vertices[vb] - m.vertices[va]).norm();
  fr.origin = 0.5 * (m.vertices[va] + m.vertices[vb]);  // P3, seed 000 §VI.G
  fr.left = (m.vertices[vb] - m.vertices[va]) / fr.ear_distance;
  r.ear_midpoint = fr.origin;
  auto fwd = face_direction(cl, ea, eb, fr);
  if (!fwd) {
    r.missing.push_back("nose tip (P4, 9.3): no dense face cluster between the ears");
    return false;
  }
  // P4 / 9.3 (seed 000 §VI.H): the mid-plane point farthest in front of its line Delta, the
  // line touching the profile above and below it (within 0.35 D).
  fr.forward = *fwd;
  fr.up = fr.forward.cross(fr.left);
  const int nose = most_protruding(m, o, fr);
  if (nose < 0) {
    r.missing.push_back("nose tip (P4, 9.3): mid-plane between the ears is empty");
    return false;
  }
  r.nose_tip = nose;
  const Eigen::Vector3d q = m.vertices[nose] - fr.origin;
  fr.forward = (q - q.dot(fr.left) * fr.left).normalized();
  fr.up = fr.forward.cross(fr.left);
  face_line_frame(m, o, fr, *r.nose_tip);
  // Up is the side where the mid-plane profile stays full (forehead), not the side where it
  // falls away under the chin to the neck: compare the profile 0.6 D above and below the tip.
  const auto prof = detail::plane_profile(m, fr, 0.0, o.plane_band * fr.ear_distance);
  const double s_tip = (m.vertices[nose] - fr.origin).dot(fr.up), h = 0.6 * fr.ear_distance;
  double f_up = 0.0, f_down = 0.0;
  for (const auto& p : prof) {
    if (std::abs(p.s - (s_tip + h)) < 0.15 * h) f_up = std::max(f_up, p.f);
    if (std::abs(p.s - (s_tip - h)) < 0.15 * h) f_down = std::max(f_down, p.f);
  }
  if (f_down > f_up) fr.up = -fr.up, fr.left = -fr.left;
  const bool a_is_left = (m.vertices[va] - fr.origin).dot(fr.left) > 0.0;
  r.ear_left = a_is_left ? va : vb;
  r.ear_right = a_is_left ? vb : va;
  if (!a_is_left) std::swap(ea, eb);  // ea = left ear cluster from here on
  r.axes.col(0) = fr.left, r.axes.col(1) = fr.up, r.axes.col(2) = fr.forward;
  r.axes_found = true;
  r.symmetry_plane << fr.left, -fr.left.dot(fr.origin);
  return true;
}

void ear_points(const TriMesh& m, const Cluster& c, const LocalFrame& fr, bool left,
                FeatureReport& r) {
  auto extreme = [&](const Eigen::Vector3d& dir) {
    int best = c.vertices.front();
    for (int v : c.vertices)
      if (m.vertices[v].dot(dir) > m.vertices[best].dot(dir)) best = v;
    return best;
  };
  const std::pair<const char*, Eigen::Vector3d> pts[] = {
      {left ? "10.1" : "10.2", fr.up}, {left ? "10.5" : "10.6", -fr.up},
      {left ? "10.3" : "10.4", -fr.forward}};
  for (const auto& [name, dir] : pts) {
    const int v = extreme(dir);
    r.points.push_back({name, mpeg4_description(name), v, m.vertices[v]});
  }
}

}  // namespace

FeatureReport mpeg4_features(const TriMesh& mesh, const FeatureOptions& options) {
  options.check();
  const AnalysisMesh am = analysis_mesh(mesh, "mpeg4_features");
  const TriMesh& m = am.mesh;
  FeatureReport r;
  const std::vector<double> ratio = geodesic_euclidean_ratio(m, options);
  r.ratio = ratio;
  LocalFrame fr;
  std::vector<Cluster> cl;
  int ea = -1, eb = -1;
  if (key_vertices(m, ratio, options, r, fr, cl, ea, eb)) {
    r.points.push_back({"9.3", mpeg4_description("9.3"), *r.nose_tip, m.vertices[*r.nose_tip]});
    ear_points(m, cl[ea], fr, true, r);
    ear_points(m, cl[eb], fr, false, r);
    detail::profile_points(m, fr, options, r);
  }
  for (const auto& w : am.warnings) r.missing.push_back("note: " + w);
  // Back to the caller's vertex numbering.
  auto orig = [&](int v) { return am.original_index[v]; };
  for (auto& p : r.points) p.vertex = orig(p.vertex);
  if (r.ear_left) r.ear_left = orig(*r.ear_left), r.ear_right = orig(*r.ear_right);
  if (r.nose_tip) r.nose_tip = orig(*r.nose_tip);
  std::vector<double> ratio_in(mesh.vertices.size(), 1.0);
  std::vector<int> cluster_in(mesh.vertices.size(), -1);
  for (size_t v = 0; v < mesh.vertices.size(); ++v)
    if (am.analysis_index[v] >= 0) {
      ratio_in[v] = r.ratio[am.analysis_index[v]];
      cluster_in[v] = r.cluster.empty() ? -1 : r.cluster[am.analysis_index[v]];
    }
  r.ratio = std::move(ratio_in);
  r.cluster = std::move(cluster_in);
  return r;
}

}  // namespace orthoface::model
