// Sub-steps of the adaptation: landmark targets, the two ways to move free vertices, blending
// and fold removal.
#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <set>
#include <stdexcept>
#include <tuple>

#include <Eigen/Geometry>

#include "model/adapt.h"
#include "model/adapt_detail.h"

namespace orthoface::model {
namespace {

// True when the base slice is at ear height: there the front silhouette shows the ear, not the
// face's extremal boundary that seed 004 assumes, so the slice's extremes get no silhouette data.
bool at_ear_height(double base_y, double margin_mm) {
  static const auto l = generic_landmarks();
  const double top = l.at("ear_left_top").y(), tragus = l.at("ear_left_tragus").y();
  const double lobe = tragus - 0.8 * (top - tragus);  // lobe below the tragus (average ear)
  return base_y <= top + margin_mm && base_y >= lobe - margin_mm;
}

// True below the jaw line of the generic head (mouth corners lowered by `margin`): there the
// front silhouette is the neck or the jaw angle far behind the face, not the face's boundary.
bool below_jaw(double base_y, double margin_mm) {
  static const double mouth = generic_landmarks().at("mouth_left").y();
  return margin_mm >= 0 && base_y < mouth - margin_mm;
}

void add_boundary_targets(const BaseMesh& base, const std::vector<Eigen::Vector3d>& aligned,
                          const StereoData& data, const AdaptOptions& options,
                          std::map<int, Eigen::Vector3d>& t) {
  for (size_t s = 0; s < base.slices.size(); ++s) {
    const int c = base.centre(static_cast<int>(s));
    const double y = aligned[c].y();
    if (y > data.y_top || y < data.y_bottom) continue;  // no data at this height
    const int right = base.slices[s].front(), left = base.slices[s].back();
    const bool ears = (options.ear_margin_mm >= 0 &&
                       at_ear_height(base.slice_heights[s], options.ear_margin_mm)) ||
                      below_jaw(base.slice_heights[s], options.jaw_margin_mm);
    if (auto x = silhouette_x_at(data, y, -1); x && !ears) t[right] = {*x, y, aligned[right].z()};
    if (auto x = silhouette_x_at(data, y, +1); x && !ears) t[left] = {*x, y, aligned[left].z()};
    if (auto z = profile_z_at(data, y)) t[c] = {centre_x_at(data, y), y, *z};  // seed 004 eq. 1
  }
}

// A feature farther from the aligned base than this is an outlier: outlier_factor times the
// median distance of the observed features (how far this face is from the generic one),
// clamped to [min_outlier_shift_mm, max_feature_shift_mm].
template <typename Observed>
double outlier_limit_mm(const Observed& observed, const AdaptOptions& options) {
  if (observed.empty()) return options.max_feature_shift_mm;
  std::vector<double> shifts;
  for (const auto& o : observed) shifts.push_back(std::get<3>(o));
  std::nth_element(shifts.begin(), shifts.begin() + shifts.size() / 2, shifts.end());
  const double median = shifts[shifts.size() / 2];
  return std::clamp(options.outlier_factor * median, options.min_outlier_shift_mm,
                    options.max_feature_shift_mm);
}

// Where a feature seen in the front view only goes, before its depth is set. The front view
// sees a cheek as the face's outline at the nose-tip row (vision/front_features.cpp), where the
// silhouette is mostly the ear lobe: vision fits the outline across the ear and keeps part of
// it (on sim heads 0.5 mm on average, up to 4 mm), as the base's slice extreme at that height
// keeps part of the generic ear (0.9 mm). So the cheek is compared like with like: its vertex
// moves sideways as far as the observed outline lies from the aligned base's extreme, instead
// of onto the observed outline. The extreme is that of the vertex's own slice (the nose-tip
// row of the base, as the observation is the face's): the outline narrows steeply there, and
// at the observed row it would follow any error of the vertical alignment.
Eigen::Vector3d front_only_target(const BaseMesh& base, const std::vector<Eigen::Vector3d>& aligned,
                                  const std::string& name, int vertex, Eigen::Vector3d observed) {
  if (name != "cheek_left" && name != "cheek_right") return observed;
  const std::vector<int>& slice = base.slices[base.slice_of_vertex[vertex]];
  const int extreme = name == "cheek_left" ? slice.back() : slice.front();  // left is +x
  observed.x() += aligned[vertex].x() - aligned[extreme].x();
  return observed;
}

}  // namespace

LandmarkTargets landmark_targets(const BaseMesh& base, const std::vector<Eigen::Vector3d>& aligned,
                                 const StereoData& data, const AdaptOptions& options,
                                 std::vector<std::string>* warnings) {
  std::map<int, Eigen::Vector3d> t;
  std::map<int, std::string> names;
  add_boundary_targets(base, aligned, data, options, t);
  std::vector<std::pair<int, Eigen::Vector3d>> no_depth;
  const std::set<std::string> ignored(options.ignored_features.begin(),
                                      options.ignored_features.end());
  std::vector<std::tuple<std::string, int, const StereoPoint*, double>> observed;  // + shift
  for (const auto& [name, v] : base.features) {
    const auto it = data.features.find(name);
    if (it == data.features.end() || ignored.count(name)) {
      if (warnings && it == data.features.end())
        warnings->push_back("feature '" + name + "' not observed: moved as a non-feature vertex");
      continue;
    }
    const Eigen::Vector3d shift = it->second.head_mm - aligned[v];
    observed.push_back(
        {name, v, &it->second, it->second.has_depth ? shift.norm() : shift.head<2>().norm()});
  }
  const double limit = outlier_limit_mm(observed, options);
  for (const auto& [name, v, point, moved] : observed) {
    if (moved > limit) {  // an outlier of vision, not a face
      if (warnings)
        warnings->push_back("feature '" + name + "' is " + std::to_string(static_cast<int>(moved)) +
                            " mm from the aligned base (limit " +
                            std::to_string(static_cast<int>(limit)) + " mm): ignored");
      continue;
    }
    names[v] = name;
    if (point->has_depth) {
      t[v] = point->head_mm;
    } else {
      no_depth.push_back({v, front_only_target(base, aligned, name, v, point->head_mm)});
      t.erase(v);
    }
  }
  LandmarkTargets out;
  for (const auto& [v, p] : t) {
    out.vertices.push_back(v);
    out.positions.push_back(p);
    out.names.push_back(names.count(v) ? names[v] : "");
  }
  if (no_depth.empty() || out.vertices.empty()) return out;
  // Front-only features: x and y from the front view (front_only_target), z from NNWA over the
  // 3D points.
  std::vector<Eigen::Vector3d> lm, disp, query;
  for (size_t i = 0; i < out.vertices.size(); ++i)
    lm.push_back(aligned[out.vertices[i]]), disp.push_back(out.positions[i] - lm.back());
  for (const auto& [v, p] : no_depth) query.push_back(aligned[v]);
  const int k = std::min<int>(options.k, static_cast<int>(lm.size()));
  const auto d = nnwa_displacements(query, lm, disp, k);
  for (size_t i = 0; i < no_depth.size(); ++i) {
    const int v = no_depth[i].first;
    const Eigen::Vector3d& p = no_depth[i].second;
    out.vertices.push_back(v);
    out.positions.push_back({p.x(), p.y(), aligned[v].z() + d[i].z()});
    out.names.push_back(names[v]);
  }
  return out;
}

int count_folds(const mesh::TriMesh& mesh, const mesh::TriMesh& reference) {
  if (mesh.vertices.size() != reference.vertices.size() ||
      mesh.triangles.size() != reference.triangles.size())
    throw std::invalid_argument("count_folds: mesh and reference differ in size");
  int folds = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& f = mesh.triangles[t];
    auto normal = [&](const mesh::TriMesh& m) {
      return (m.vertices[f[1]] - m.vertices[f[0]]).cross(m.vertices[f[2]] - m.vertices[f[0]]);
    };
    if (normal(mesh).dot(normal(reference)) <= 0) ++folds;
  }
  return folds;
}

namespace detail {

std::vector<Eigen::Vector3d> apply(const Alignment& a, const std::vector<Eigen::Vector3d>& v) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(v.size());
  for (const auto& p : v) out.push_back(a.scale.cwiseProduct(p) + a.translation);
  return out;
}

namespace {

// Observed, not ignored features that `targets` does not use: the outliers.
std::vector<std::string> outlier_features(const BaseMesh& base, const StereoData& data,
                                          const AdaptOptions& options,
                                          const LandmarkTargets& targets) {
  const std::set<std::string> used(targets.names.begin(), targets.names.end());
  const std::set<std::string> ignored(options.ignored_features.begin(),
                                      options.ignored_features.end());
  std::vector<std::string> out;
  for (const auto& [name, v] : base.features)
    if (data.features.count(name) && !ignored.count(name) && !used.count(name)) out.push_back(name);
  return out;
}

}  // namespace

AlignedTargets align_and_target(const BaseMesh& base, const StereoData& data,
                                const AdaptOptions& options, std::vector<std::string>* warnings) {
  AlignedTargets a;
  std::vector<std::string> notes;
  a.alignment = align_base(base, data, options.ignored_features);
  a.aligned = detail::apply(a.alignment, base.mesh.vertices);
  a.targets = landmark_targets(base, a.aligned, data, options, &notes);
  const std::vector<std::string> outliers = outlier_features(base, data, options, a.targets);
  if (!outliers.empty()) {
    AdaptOptions without = options;
    without.ignored_features.insert(without.ignored_features.end(), outliers.begin(),
                                    outliers.end());
    a.alignment = align_base(base, data, without.ignored_features);
    a.aligned = detail::apply(a.alignment, base.mesh.vertices);
    std::vector<std::string> second;
    a.targets = landmark_targets(base, a.aligned, data, without, &second);
    for (auto& w : second)
      if (std::find(notes.begin(), notes.end(), w) == notes.end()) notes.push_back(std::move(w));
  }
  if (warnings) warnings->insert(warnings->end(), notes.begin(), notes.end());
  return a;
}

std::vector<std::vector<int>> vertex_adjacency(const mesh::TriMesh& mesh) {
  std::vector<std::vector<int>> adj(mesh.vertices.size());
  for (const auto& f : mesh.triangles)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j && std::find(adj[f[i]].begin(), adj[f[i]].end(), f[j]) == adj[f[i]].end())
          adj[f[i]].push_back(f[j]);
  return adj;
}

std::vector<Eigen::Vector3d> move_by_nnwa(const std::vector<Eigen::Vector3d>& aligned,
                                          const LandmarkTargets& targets, int k,
                                          const std::vector<char>& skip) {
  if (!skip.empty() && skip.size() != aligned.size())
    throw std::invalid_argument("move_by_nnwa: " + std::to_string(skip.size()) +
                                " skip flags for " + std::to_string(aligned.size()) + " vertices");
  std::vector<Eigen::Vector3d> lm, disp;
  for (size_t i = 0; i < targets.vertices.size(); ++i) {
    lm.push_back(aligned[targets.vertices[i]]);
    disp.push_back(targets.positions[i] - lm.back());  // seed 002 eq. 3.7 (custom - original)
  }
  std::vector<Eigen::Vector3d> out = aligned, query;
  std::vector<int> moved;
  for (size_t j = 0; j < aligned.size(); ++j)
    if (skip.empty() || !skip[j]) moved.push_back(static_cast<int>(j)), query.push_back(aligned[j]);
  const auto d = nnwa_displacements(query, lm, disp, k);
  for (size_t i = 0; i < moved.size(); ++i) out[moved[i]] += d[i];  // eq. 3.9
  for (size_t i = 0; i < targets.vertices.size(); ++i)
    out[targets.vertices[i]] = targets.positions[i];
  return out;
}

std::vector<Eigen::Vector3d> move_by_interpolation(const BaseMesh& base,
                                                   const std::vector<Eigen::Vector3d>& aligned,
                                                   const LandmarkTargets& targets, int k) {
  std::map<int, Eigen::Vector3d> fixed;
  for (size_t i = 0; i < targets.vertices.size(); ++i)
    fixed[targets.vertices[i]] = targets.positions[i];
  // The inner vertices of a slice with a profile point are eq. 2's; NNWA moves the rest.
  auto has_profile = [&](const std::vector<int>& ids) { return fixed.count(ids[ids.size() / 2]); };
  std::vector<char> by_eq2(aligned.size(), 0);
  for (const std::vector<int>& ids : base.slices)
    if (has_profile(ids))
      for (size_t i = 1; i + 1 < ids.size(); ++i) by_eq2[ids[i]] = !fixed.count(ids[i]);
  std::vector<Eigen::Vector3d> out = move_by_nnwa(aligned, targets, k, by_eq2);
  for (size_t s = 0; s < base.slices.size(); ++s) {
    const std::vector<int>& ids = base.slices[s];
    const int mid = static_cast<int>(ids.size()) / 2;
    if (!has_profile(ids)) continue;  // no profile point: NNWA
    // An extreme without silhouette data (ear heights, below the jaw) is the boundary vertex
    // NNWA placed: the profile point still stretches the slice between it and the centre line,
    // which NNWA alone does not do when named features lie nearer than the centre line (the
    // depth between profile and silhouette is what a turned view shows as its outline).
    for (int end : {ids.front(), ids.back()})
      if (!fixed.count(end)) fixed[end] = out[end];
    for (int i = 1; i + 1 < static_cast<int>(ids.size()); ++i) {
      if (!by_eq2[ids[i]]) continue;
      const int bl = i < mid ? ids.front() : ids[mid], br = i < mid ? ids[mid] : ids.back();
      const Eigen::Vector3d &l = fixed[bl], &r = fixed[br];
      const Eigen::Vector3d &l0 = aligned[bl], &r0 = aligned[br], &a0 = aligned[ids[i]];
      const double t = (a0.x() - l0.x()) / (r0.x() - l0.x());
      Eigen::Vector3d p;
      p.x() = interpolate_between(l.x(), r.x(), l0.x(), r0.x(), a0.x());  // seed 004 eq. 2
      // The same linear rule for depth; height keeps the boundary's vertical shift.
      p.z() = std::abs(r0.z() - l0.z()) > 1e-6
                  ? interpolate_between(l.z(), r.z(), l0.z(), r0.z(), a0.z())
                  : a0.z() + (1 - t) * (l.z() - l0.z()) + t * (r.z() - r0.z());
      p.y() = a0.y() + (1 - t) * (l.y() - l0.y()) + t * (r.y() - r0.y());
      out[ids[i]] = p;
    }
  }
  return out;
}

namespace {

// The displacement moved - aligned after `iterations` passes that take each movable vertex's
// halfway to its neighbours' mean (the others keep theirs).
std::vector<Eigen::Vector3d> relaxed_displacement(const std::vector<std::vector<int>>& adjacency,
                                                  const std::vector<Eigen::Vector3d>& aligned,
                                                  const std::vector<Eigen::Vector3d>& moved,
                                                  const std::vector<char>& movable,
                                                  int iterations) {
  const size_t n = moved.size();
  std::vector<Eigen::Vector3d> d(n);
  for (size_t v = 0; v < n; ++v) d[v] = moved[v] - aligned[v];
  for (int it = 0; it < iterations; ++it) {
    std::vector<Eigen::Vector3d> next = d;
    for (size_t v = 0; v < n; ++v) {
      if (!movable[v] || adjacency[v].empty()) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int w : adjacency[v]) mean += d[size_t(w)];
      next[v] = 0.5 * d[v] + 0.5 * mean / static_cast<double>(adjacency[v].size());
    }
    d.swap(next);
  }
  return d;
}

}  // namespace

void blend_near_features(const std::vector<std::vector<int>>& adjacency,
                         const std::vector<Eigen::Vector3d>& aligned,
                         const LandmarkTargets& targets, const AdaptOptions& options,
                         std::vector<Eigen::Vector3d>& moved) {
  const int n = static_cast<int>(moved.size());
  std::vector<int> ring(n, -1);
  std::vector<bool> is_target(n, false);
  std::queue<int> q;
  for (size_t i = 0; i < targets.vertices.size(); ++i) {
    is_target[targets.vertices[i]] = true;
    if (!targets.names[i].empty()) ring[targets.vertices[i]] = 0, q.push(targets.vertices[i]);
  }
  while (!q.empty()) {
    const int v = q.front();
    q.pop();
    if (ring[v] >= options.blend_rings) continue;
    for (int w : adjacency[v])
      if (ring[w] < 0) ring[w] = ring[v] + 1, q.push(w);
  }
  std::vector<char> movable(size_t(n), 0);
  for (int v = 0; v < n; ++v) movable[size_t(v)] = ring[v] > 0 && !is_target[v];
  const std::vector<Eigen::Vector3d> d =
      relaxed_displacement(adjacency, aligned, moved, movable, options.blend_iterations);
  for (int v = 0; v < n; ++v) moved[v] = aligned[v] + d[v];
}

Smoothing smooth_if_rough(const std::vector<std::vector<int>>& adjacency,
                          const std::vector<Eigen::Vector3d>& aligned,
                          const LandmarkTargets& targets, const AdaptOptions& options,
                          std::vector<Eigen::Vector3d>& moved) {
  const size_t n = moved.size();
  std::vector<char> movable(n, 1);
  for (int v : targets.vertices) movable[size_t(v)] = 0;
  const std::vector<Eigen::Vector3d> d =
      relaxed_displacement(adjacency, aligned, moved, movable, options.smooth_iterations);
  std::vector<double> deviation;
  for (size_t v = 0; v < n; ++v)
    if (movable[v]) deviation.push_back((aligned[v] + d[v] - moved[v]).norm());
  Smoothing s;
  if (deviation.empty()) return s;
  std::nth_element(deviation.begin(), deviation.begin() + deviation.size() / 2, deviation.end());
  s.roughness_mm = deviation[deviation.size() / 2];
  s.share = std::clamp(
      (s.roughness_mm - options.rough_from_mm) / (options.rough_full_mm - options.rough_from_mm),
      0.0, 1.0);
  for (size_t v = 0; v < n; ++v) moved[v] += s.share * (aligned[v] + d[v] - moved[v]);
  return s;
}

std::pair<int, int> remove_folds(const std::vector<std::vector<int>>& adjacency,
                                 const std::vector<Eigen::Vector3d>& reference,
                                 const LandmarkTargets& targets, int max_passes,
                                 mesh::TriMesh& mesh) {
  std::vector<char> is_target(mesh.vertices.size(), 0);
  for (int v : targets.vertices) is_target[v] = 1;
  auto normal = [](const std::vector<Eigen::Vector3d>& p, const std::array<int, 3>& f) {
    return (p[f[1]] - p[f[0]]).cross(p[f[2]] - p[f[0]]);
  };
  std::vector<int> folds;
  auto find_folds = [&]() {
    folds.clear();
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      if (normal(mesh.vertices, mesh.triangles[t]).dot(normal(reference, mesh.triangles[t])) <= 0)
        folds.push_back(static_cast<int>(t));
  };
  find_folds();
  const int initial = static_cast<int>(folds.size());
  std::vector<int> loose;
  bool move_targets = false;  // data points give way last: when free vertices alone do not
                              // reduce the folds, or after half the passes
  for (int pass = 0; pass < max_passes && !folds.empty(); ++pass) {
    move_targets = move_targets || pass >= max_passes / 2;
    loose.clear();
    for (int t : folds)
      for (int v : mesh.triangles[t]) {
        loose.push_back(v);
        loose.insert(loose.end(), adjacency[v].begin(), adjacency[v].end());
      }
    std::sort(loose.begin(), loose.end());
    loose.erase(std::unique(loose.begin(), loose.end()), loose.end());
    for (int v : loose) {
      if (is_target[v] && !move_targets) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int w : adjacency[v]) mean += mesh.vertices[w];
      mesh.vertices[v] = 0.5 * mesh.vertices[v] + 0.5 * mean / double(adjacency[v].size());
    }
    const size_t before = folds.size();
    find_folds();
    move_targets = move_targets || folds.size() >= before;
  }
  return {initial, static_cast<int>(folds.size())};
}

int open_slice_fins(const BaseMesh& base, mesh::TriMesh& mesh) {
  int moved = 0;
  for (const std::vector<int>& slice : base.slices) {
    const int c = static_cast<int>(slice.size()) / 2;
    for (int side : {-1, 1}) {
      double reach = mesh.vertices[slice[c]].x();
      for (int i = c + side; i >= 0 && i < static_cast<int>(slice.size()); i += side) {
        double& x = mesh.vertices[slice[i]].x();
        if (side * (x - reach) < 0) {
          x = reach;
          ++moved;
        }
        reach = x;
      }
    }
  }
  return moved;
}

}  // namespace detail

int clamp_to_silhouette(const StereoData& data, mesh::TriMesh& mesh, double margin_mm) {
  if (!(margin_mm >= 0)) throw std::invalid_argument("clamp to silhouette: margin_mm must be >= 0");
  int moved = 0;
  for (Eigen::Vector3d& v : mesh.vertices) {
    const auto right = silhouette_x_at(data, v.y(), -1), left = silhouette_x_at(data, v.y(), 1);
    if (right && v.x() < *right - margin_mm) v.x() = *right - margin_mm, ++moved;
    if (left && v.x() > *left + margin_mm) v.x() = *left + margin_mm, ++moved;
  }
  return moved;
}

}  // namespace orthoface::model
