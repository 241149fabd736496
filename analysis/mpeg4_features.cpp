// Seed 000: key vertices (both ears, their midpoint, the nose tip), local axes, symmetry plane and
// MPEG-4 feature points of a head mesh, independent of its pose and scale.
#include "analysis/mpeg4_features.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <nlohmann/json.hpp>

#include "analysis/analysis_mesh.h"
#include "analysis/feature_detail.h"
#include "analysis/geodesics.h"
#include "analysis/mpeg4_names.h"
#include "analysis/point_grid.h"

namespace orthoface::analysis {
namespace {

using detail::LocalFrame;
using detail::PointGrid;

struct Cluster {
  std::vector<int> vertices;
  double mass = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

std::vector<double> vertex_areas(const mesh::TriMesh& m) {
  std::vector<double> a(m.vertices.size(), 0.0);
  for (const auto& t : m.triangles) {
    const double area =
        0.5 *
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).norm();
    for (int v : t) a[v] += area / 3.0;
  }
  return a;
}

std::vector<int> all_vertices(const mesh::TriMesh& m) {
  std::vector<int> v(m.vertices.size());
  std::iota(v.begin(), v.end(), 0);
  return v;
}

// Groups of vertices with ratio >= t joined when closer than `gap` (z_clusters), heaviest
// first; mass = sum of (ratio - 1) x vertex area. The gap lets one ear stay one cluster when its
// dense rim is broken into several folds (helix, antihelix, the groove behind the ear).
std::vector<Cluster> dense_clusters(const mesh::TriMesh& m, const std::vector<double>& ratio,
                                    double t, double gap) {
  const auto area = vertex_areas(m);
  std::vector<int> dense;
  for (size_t v = 0; v < m.vertices.size(); ++v)
    if (ratio[v] >= t) dense.push_back(int(v));
  const PointGrid grid(m.vertices, gap, dense);
  std::vector<int> seen(m.vertices.size(), 0);
  std::vector<Cluster> out;
  for (int s : dense) {
    if (seen[s]) continue;
    Cluster c;
    std::vector<int> stack{s};
    seen[s] = 1;
    while (!stack.empty()) {
      const int v = stack.back();
      stack.pop_back();
      c.vertices.push_back(v);
      const double w = (ratio[v] - 1.0) * area[v];
      c.mass += w, c.centroid += w * m.vertices[v];
      grid.for_each_near(m.vertices[v], gap, [&](int u) {
        if (!seen[u]) seen[u] = 1, stack.push_back(u);
      });
    }
    if (c.mass > 0.0) c.centroid /= c.mass;
    out.push_back(std::move(c));
  }
  std::sort(out.begin(), out.end(),
            [](const Cluster& a, const Cluster& b) { return a.mass > b.mass; });
  return out;
}

// The ratio above which `fraction` of the surface area lies: a threshold that does not depend on
// where the mesh is finely tessellated (a scan's face often has most of its vertices).
double top_area_ratio(const mesh::TriMesh& m, const std::vector<double>& ratio, double fraction) {
  const auto area = vertex_areas(m);
  std::vector<int> order(ratio.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return ratio[a] > ratio[b]; });
  const double total = std::accumulate(area.begin(), area.end(), 0.0);
  double sum = 0.0;
  for (int v : order)
    if ((sum += area[v]) >= fraction * total) return ratio[v];
  return ratio[order.back()];
}

int nearest_vertex(const mesh::TriMesh& m, const std::vector<int>& among,
                   const Eigen::Vector3d& p) {
  int best = among.front();
  for (int v : among)
    if ((m.vertices[v] - p).squaredNorm() < (m.vertices[best] - p).squaredNorm()) best = v;
  return best;
}

std::vector<Eigen::Vector3d> area_normals(const mesh::TriMesh& m) {
  std::vector<Eigen::Vector3d> n(m.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d fn =
        (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    for (int v : t) n[v] += fn;
  }
  for (auto& x : n) x = x.norm() > 0 ? Eigen::Vector3d(x.normalized()) : Eigen::Vector3d::Zero();
  return n;
}

// A candidate mirror plane n.(p - o) = 0 and its error (mean mirror distance / d).
struct MirrorPlane {
  Eigen::Vector3d n, o;
  double error = 1.0;
};

// Mirror symmetry of the whole mesh (seed 000: the face is symmetric), tested on ~400 sample
// vertices against the vertex nearest to each mirror image.
class MirrorTest {
 public:
  MirrorTest(const mesh::TriMesh& m, double d)
      : m_(m), d_(d), grid_(m.vertices, 0.1 * d, all_vertices(m)), normals_(area_normals(m)) {
    const size_t step = std::max<size_t>(1, m.vertices.size() / 400);
    for (size_t v = 0; v < m.vertices.size(); v += step) samples_.push_back(int(v));
  }

  // Mean point-to-tangent-plane distance from the mirrored samples to their nearest vertex, / d;
  // a mirror image farther than 0.04 d from the mesh counts as 0.04. The tangent plane removes
  // the vertex-spacing floor.
  double error(const Eigen::Vector3d& n, const Eigen::Vector3d& o) const {
    const double cap = 0.04 * d_;
    double sum = 0.0;
    for (int v : samples_) {
      const Eigen::Vector3d q = reflect(m_.vertices[v], n, o);
      const int u = grid_.nearest(q, cap);
      sum += u < 0 ? cap : std::min(cap, std::abs(normals_[u].dot(q - m_.vertices[u])));
    }
    return sum / double(samples_.size()) / d_;
  }

  // Reflective ICP: pairs each sample with the vertex nearest to its mirror image (within
  // `reach` x d) and refits the plane to the pairs' midpoints, a few rounds with a shrinking
  // reach. Corrects a plane bisecting two real, slightly asymmetric ears.
  MirrorPlane refine(Eigen::Vector3d n, Eigen::Vector3d o) const {
    for (double reach : {0.08, 0.05, 0.03, 0.03, 0.02}) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      std::vector<Eigen::Vector3d> mids;
      for (int v : samples_) {
        const Eigen::Vector3d p = m_.vertices[v];
        const int u = grid_.nearest(reflect(p, n, o), reach * d_);
        if (u < 0) continue;
        mids.push_back(0.5 * (p + m_.vertices[u]));
        mean += mids.back();
      }
      if (mids.size() < 20) break;
      mean /= double(mids.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& c : mids) cov += (c - mean) * (c - mean).transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
      Eigen::Vector3d next = es.eigenvectors().col(0);  // the flattest direction of the midpoints
      if (next.dot(n) < 0.0) next = -next;
      if (next.dot(n) < 0.9) break;  // not a small correction: keep the plane as it was
      n = next, o = mean;
    }
    return {n, o, error(n, o)};
  }

  static Eigen::Vector3d reflect(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                 const Eigen::Vector3d& o) {
    return p - 2.0 * n.dot(p - o) * n;
  }

 private:
  const mesh::TriMesh& m_;
  double d_;
  PointGrid grid_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<int> samples_;
};

// The ear pair (seed 000 §VI.G): the two clusters of similar mass, far apart, that are mirror
// images of each other under a mirror plane of the whole mesh; the farthest, heaviest such pair.
// Returns the pair and the refined symmetry plane.
std::optional<std::pair<std::pair<int, int>, MirrorPlane>> ear_pair(const mesh::TriMesh& m,
                                                                    const std::vector<Cluster>& cl,
                                                                    double diag) {
  struct Cand {
    double score;
    int a, b;
  };
  std::vector<Cand> cands;
  const size_t top = std::min<size_t>(cl.size(), 20);
  for (size_t a = 0; a < top; ++a)
    for (size_t b = a + 1; b < top; ++b) {
      const double lo = std::min(cl[a].mass, cl[b].mass), hi = std::max(cl[a].mass, cl[b].mass);
      const double d = (cl[a].centroid - cl[b].centroid).norm();
      if (lo < 0.3 * hi || lo < 0.02 * cl[0].mass || d < 0.15 * diag) continue;
      cands.push_back({d * std::sqrt(lo), int(a), int(b)});
    }
  std::sort(cands.begin(), cands.end(),
            [](const Cand& x, const Cand& y) { return x.score > y.score; });
  const MirrorTest test(m, 0.3 * diag);
  int refined = 0;
  for (const Cand& c : cands) {
    const Eigen::Vector3d pa = cl[c.a].centroid, pb = cl[c.b].centroid;
    const double d = (pb - pa).norm();
    const Eigen::Vector3d n = (pb - pa) / d, o = 0.5 * (pa + pb);
    if (test.error(n, o) > 0.06 || ++refined > 12) continue;  // far from any mirror plane
    const MirrorPlane plane = test.refine(n, o);
    // The pair must map onto itself under the refined plane, and the mesh onto itself.
    const double miss = (MirrorTest::reflect(pa, plane.n, plane.o) - pb).norm();
    if (plane.error < 0.02 && miss < 0.12 * d)
      return std::make_pair(std::make_pair(c.a, c.b), plane);
  }
  return std::nullopt;
}

// Forward direction: from P3 to the heaviest cluster on the bisecting plane (eyes, nose, lips).
std::optional<Eigen::Vector3d> face_direction(const std::vector<Cluster>& cl, int ea, int eb,
                                              const LocalFrame& fr) {
  for (size_t c = 0; c < cl.size(); ++c) {
    if (int(c) == ea || int(c) == eb) continue;
    const Eigen::Vector3d q = cl[c].centroid - fr.origin;
    // The face lies within ~0.85 D of P3; a crown, hat brim or bust base is farther.
    if (std::abs(q.dot(fr.left)) > 0.15 * fr.ear_distance || q.norm() < 0.3 * fr.ear_distance ||
        q.norm() > 1.0 * fr.ear_distance)
      continue;
    const Eigen::Vector3d f = q - q.dot(fr.left) * fr.left;
    if (f.norm() > 0.0) return f.normalized();
  }
  return std::nullopt;
}

// Seed 000 §VI.H line Delta for profile sample c: the points where the lines from c touch the
// profile above and below it (0.05-0.7 D away), i.e. c's neighbours on the profile's convex hull
// (brow and chin side for the nose tip). Null when a side is empty.
std::pair<const detail::ProfileSample*, const detail::ProfileSample*> delta_line(
    const std::vector<detail::ProfileSample>& prof, const detail::ProfileSample& c, double D) {
  const detail::ProfileSample* above = nullptr;
  const detail::ProfileSample* below = nullptr;
  double best_a = 1e300, best_b = 1e300;
  for (const auto& p : prof) {
    const double ds = p.s - c.s;
    if (std::abs(ds) < 0.05 * D || std::abs(ds) > 0.7 * D) continue;
    const double slope = (c.f - p.f) / std::abs(ds);  // smallest: the tangent from c
    if (ds > 0 && slope < best_a) best_a = slope, above = &p;
    if (ds < 0 && slope < best_b) best_b = slope, below = &p;
  }
  return {above, below};
}

// Up becomes the direction of the nose tip's line Delta and forward its normal toward the nose,
// so peaks and troughs are measured from the face line rather than from the tilted ear-nose axis.
void face_line_frame(const mesh::TriMesh& m, const FeatureOptions& o, LocalFrame& fr, int nose) {
  const auto prof = detail::plane_profile(m, fr, 0.0, o.plane_band * fr.ear_distance);
  const Eigen::Vector3d q = m.vertices[nose] - fr.origin;
  const detail::ProfileSample tip{nose, q.dot(fr.up), q.dot(fr.forward)};
  const auto [above, below] = delta_line(prof, tip, fr.ear_distance);
  if (!above || !below) return;  // keep the ear-nose frame
  const Eigen::Vector3d up =
      ((above->s - below->s) * fr.up + (above->f - below->f) * fr.forward).normalized();
  fr.up = up;
  fr.forward = fr.left.cross(up);
}

// P4 / 9.3 (seed 000 §VI.H): the mid-plane vertex farthest in front of its line Delta. The
// distance to Delta does not depend on how the forward axis is tilted within the mid-plane, and
// on a smoothly convex stretch (forehead, skull) Delta hugs the profile. -1 if none qualifies.
int most_protruding(const mesh::TriMesh& m, const FeatureOptions& o, const LocalFrame& fr) {
  const double D = fr.ear_distance;
  const auto prof = detail::plane_profile(m, fr, 0.0, o.plane_band * D);
  int best = -1;
  double best_h = 0.0;
  for (const auto& c : prof) {
    // Face points lie within ~0.85 D of the ear midpoint; a neck cut or a bust base is farther.
    if ((m.vertices[c.vertex] - fr.origin).norm() > 0.95 * D) continue;
    const auto [above, below] = delta_line(prof, c, D);
    if (!above || !below) continue;
    const Eigen::Vector2d a(above->s, above->f), b(below->s, below->f), x(c.s, c.f);
    const Eigen::Vector2d dir = (a - b).normalized(), normal(-dir.y(), dir.x());  // toward +f
    const double h = (x - b).dot(normal);
    if (h > best_h) best_h = h, best = c.vertex;
  }
  return best;
}

// Builds the frame and the key vertices; returns false (with report.missing) when it cannot.
bool key_vertices(const mesh::TriMesh& m, const std::vector<double>& ratio, const FeatureOptions& o,
                  FeatureReport& r, LocalFrame& fr, std::vector<Cluster>& cl, int& ea, int& eb) {
  const double diag = pose_free_size(m);
  const double t =
      std::clamp(top_area_ratio(m, ratio, o.dense_area), o.ratio_threshold, o.ratio_cap);
  cl = dense_clusters(m, ratio, t, o.neighbourhood * diag);
  r.cluster.assign(m.vertices.size(), -1);
  for (size_t c = 0; c < cl.size(); ++c)
    for (int v : cl[c].vertices) r.cluster[v] = int(c);
  const auto pair = ear_pair(m, cl, diag);
  if (!pair) {
    r.missing.push_back("ears (P1, P2): no symmetric pair of dense clusters (" +
                        std::to_string(cl.size()) +
                        " clusters); a face without ears cannot "
                        "give the ears, their midpoint, the axes or the points that need them");
    return false;
  }
  std::tie(ea, eb) = pair->first;
  const MirrorPlane& plane = pair->second;
  r.symmetry_error = plane.error;
  const int va = nearest_vertex(m, cl[ea].vertices, cl[ea].centroid);
  const int vb = nearest_vertex(m, cl[eb].vertices, cl[eb].centroid);
  fr.ear_distance = (m.vertices[vb] - m.vertices[va]).norm();
  // P3 (seed 000 §VI.G): the ears' midpoint, moved onto the refined symmetry plane whose normal
  // is the left axis (the profiles are thin slices of that plane).
  fr.left =
      plane.n.dot(m.vertices[vb] - m.vertices[va]) > 0.0 ? plane.n : Eigen::Vector3d(-plane.n);
  const Eigen::Vector3d mid = 0.5 * (m.vertices[va] + m.vertices[vb]);
  fr.origin = mid - fr.left.dot(mid - plane.o) * fr.left;
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

void ear_points(const mesh::TriMesh& m, const Cluster& c, const LocalFrame& fr, bool left,
                FeatureReport& r) {
  auto extreme = [&](const Eigen::Vector3d& dir) {
    int best = c.vertices.front();
    for (int v : c.vertices)
      if (m.vertices[v].dot(dir) > m.vertices[best].dot(dir)) best = v;
    return best;
  };
  const std::pair<const char*, Eigen::Vector3d> pts[] = {{left ? "10.1" : "10.2", fr.up},
                                                         {left ? "10.5" : "10.6", -fr.up},
                                                         {left ? "10.3" : "10.4", -fr.forward}};
  for (const auto& [name, dir] : pts) {
    const int v = extreme(dir);
    r.points.push_back({name, mpeg4_description(name), v, m.vertices[v]});
  }
}

}  // namespace

FeatureReport mpeg4_features(const mesh::TriMesh& mesh, const FeatureOptions& options) {
  options.check();
  const AnalysisMesh am = analysis_mesh(mesh, "mpeg4_features");
  const mesh::TriMesh& m = am.mesh;
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

std::string feature_report_json(const mesh::TriMesh& mesh, const FeatureReport& r) {
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  const auto at = [&](int v) {
    if (v < 0 || size_t(v) >= mesh.vertices.size())
      throw std::invalid_argument("feature report: vertex " + std::to_string(v) +
                                  " is not in the mesh of " + std::to_string(mesh.vertices.size()) +
                                  " vertices");
    return vec(mesh.vertices[size_t(v)]);
  };
  // Built member by member: a braced list holding the temporaries these calls return kept
  // references past their lifetime (AddressSanitizer: stack-use-after-scope).
  const auto key = [&](const std::optional<int>& v) {
    nlohmann::json k(nullptr);
    if (v) {
      k = nlohmann::json::object();
      k["vertex"] = *v;
      k["position"] = at(*v);
    }
    return k;
  };
  nlohmann::json j;
  j["key_vertices"]["P1_ear_left"] = key(r.ear_left);
  j["key_vertices"]["P2_ear_right"] = key(r.ear_right);
  j["key_vertices"]["P4_nose_tip"] = key(r.nose_tip);
  if (r.axes_found) {
    j["key_vertices"]["P3_ear_midpoint"] = vec(r.ear_midpoint);
    j["axes"]["origin"] = vec(r.ear_midpoint);
    j["axes"]["left"] = vec(r.axes.col(0));
    j["axes"]["up"] = vec(r.axes.col(1));
    j["axes"]["forward"] = vec(r.axes.col(2));
    j["symmetry_plane"]["normal"] = vec(r.symmetry_plane.head<3>());
    j["symmetry_plane"]["d"] = r.symmetry_plane[3];
    j["symmetry_plane"]["mirror_error"] = r.symmetry_error;
  }
  j["feature_points"] = nlohmann::json::array();
  for (const auto& p : r.points) {
    nlohmann::json point;
    point["name"] = p.name;
    point["description"] = p.description;
    point["vertex"] = p.vertex;
    at(p.vertex);  // refuses an index outside the mesh
    point["position"] = vec(p.position);
    j["feature_points"].push_back(std::move(point));
  }
  j["missing"] = r.missing;
  return j.dump(2);
}

}  // namespace orthoface::analysis
