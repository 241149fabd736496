#include "model/adapt.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "model/adapt_detail.h"

namespace orthoface::model {
namespace {

struct Spread {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero(), rms = Eigen::Vector2d::Zero();
};

Spread spread_of(const std::vector<Eigen::Vector2d>& pts) {
  Spread s;
  for (const auto& p : pts) s.centre += p;
  s.centre /= static_cast<double>(pts.size());
  for (const auto& p : pts) s.rms += (p - s.centre).cwiseAbs2();
  s.rms = (s.rms / static_cast<double>(pts.size())).cwiseSqrt();
  return s;
}

// Without usable features. The observed heights are no guide (the photos show the whole head,
// the base mesh only the face), so the nose anchors the base: its tip goes to the profile's most
// projecting point (seed 004 §4 finds the nose the same way), and one scale for x, y and z is
// the silhouette's width at that height over the generic head's.
Alignment align_by_boundary(const StereoData& data) {
  static const Eigen::Vector3d nose = generic_landmarks().at("nose_tip");
  Alignment a;
  const Eigen::Vector2d* tip = nullptr;  // profile points are (z, y)
  for (const Eigen::Vector2d& p : data.profile)
    if (p.y() <= data.y_top && p.y() >= data.y_bottom && (!tip || p.x() > tip->x())) tip = &p;
  if (!tip) return a;
  const auto l = silhouette_x_at(data, tip->y(), +1), r = silhouette_x_at(data, tip->y(), -1);
  if (l && r && *l > *r) a.scale.setConstant((*l - *r) / (2.0 * generic_half_width(nose.y())));
  a.translation =
      Eigen::Vector3d(centre_x_at(data, tip->y()), tip->y(), tip->x()) - a.scale.cwiseProduct(nose);
  return a;
}

}  // namespace

void AdaptOptions::check() const {
  if (k < 1) throw std::invalid_argument("AdaptOptions: k must be >= 1, got " + std::to_string(k));
  if (!(max_feature_shift_mm > 0))
    throw std::invalid_argument("AdaptOptions: max_feature_shift_mm must be > 0");
  if (!(min_outlier_shift_mm > 0 && min_outlier_shift_mm <= max_feature_shift_mm))
    throw std::invalid_argument(
        "AdaptOptions: min_outlier_shift_mm must be in (0, max_feature_shift_mm]");
  if (!(silhouette_margin_mm >= 0 && silhouette_margin_mm <= 50))
    throw std::invalid_argument("AdaptOptions: silhouette_margin_mm must be in 0..50");
  if (!(outlier_factor > 0))
    throw std::invalid_argument("AdaptOptions: outlier_factor must be > 0");
  if (blend_rings < 0 || blend_iterations < 0 || max_fold_passes < 0 || smooth_iterations < 0)
    throw std::invalid_argument(
        "AdaptOptions: blend_rings, blend_iterations, max_fold_passes and "
        "smooth_iterations must be >= 0");
  if (!(rough_from_mm >= 0 && rough_full_mm > rough_from_mm))
    throw std::invalid_argument(
        "AdaptOptions: rough_from_mm and rough_full_mm must satisfy 0 <= from < full");
}

double interpolate_between(double x_l, double x_r, double base_l, double base_r, double base_x) {
  if (base_r == base_l)
    throw std::invalid_argument("interpolate_between: the base boundary vertices coincide");
  return x_l + (x_r - x_l) * (base_x - base_l) / (base_r - base_l);  // seed 004 eq. 2
}

namespace {

// The k nearest landmarks of a point, kept sorted by squared distance (insertion; k is small).
class NearestK {
 public:
  explicit NearestK(int k) : best_(k) {}
  void reset() { filled_ = 0; }
  bool full() const { return filled_ == static_cast<int>(best_.size()); }
  void offer(double d2, int i) {
    const int k = static_cast<int>(best_.size());
    if (full() && d2 >= best_[k - 1].first) return;
    int pos = full() ? k - 1 : filled_++;
    while (pos > 0 && best_[pos - 1].first > d2) best_[pos] = best_[pos - 1], --pos;
    best_[pos] = {d2, i};
  }
  const std::pair<double, int>& operator[](int n) const { return best_[n]; }

 private:
  std::vector<std::pair<double, int>> best_;
  int filled_ = 0;
};

}  // namespace

std::vector<Eigen::Vector3d> nnwa_displacements(const std::vector<Eigen::Vector3d>& points,
                                                const std::vector<Eigen::Vector3d>& landmarks,
                                                const std::vector<Eigen::Vector3d>& displacements,
                                                int k) {
  if (landmarks.size() != displacements.size())
    throw std::invalid_argument("nnwa_displacements: landmarks and displacements differ in size");
  if (k < 1 || k > static_cast<int>(landmarks.size()))
    throw std::invalid_argument("nnwa_displacements: k = " + std::to_string(k) +
                                " must be in [1, " + std::to_string(landmarks.size()) +
                                "] (the landmark count)");
  const int n = static_cast<int>(landmarks.size());
  Eigen::ArrayXd lx(n), ly(n), lz(n), d2(n);  // one coordinate per array: vectorised distances
  for (int i = 0; i < n; ++i)
    lx[i] = landmarks[i].x(), ly[i] = landmarks[i].y(), lz[i] = landmarks[i].z();
  std::vector<Eigen::Vector3d> out(points.size());
  NearestK best(k);
  for (size_t j = 0; j < points.size(); ++j) {
    const Eigen::Vector3d& p = points[j];
    d2 = (lx - p.x()).square() + (ly - p.y()).square() + (lz - p.z()).square();
    // Consecutive points are mostly near in space (vertex order): the previous point's k
    // nearest landmarks are k candidates within `bound` of this one, so the k nearest are too,
    // and only the few landmarks within it are offered.
    double bound = std::numeric_limits<double>::infinity();
    if (j > 0) {
      bound = 0;
      for (int m = 0; m < k; ++m) bound = std::max(bound, d2[best[m].second]);
    }
    best.reset();
    for (int i = 0; i < n; ++i)
      if (d2[i] <= bound) best.offer(d2[i], i);
    if (best[0].first < 1e-18) {  // on a landmark: its own displacement (the limit of eq. 3.8)
      out[j] = displacements[best[0].second];
      continue;
    }
    Eigen::Vector3d num = Eigen::Vector3d::Zero();
    double den = 0.0;
    for (int n = 0; n < k; ++n) {  // seed 002 eq. 3.8, weights 1 / d^2
      num += displacements[best[n].second] / best[n].first;
      den += 1.0 / best[n].first;
    }
    out[j] = num / den;
  }
  return out;
}

Alignment align_base(const BaseMesh& base, const StereoData& data,
                     const std::vector<std::string>& excluded) {
  std::vector<Eigen::Vector2d> b, o;
  double zb = 0, zo = 0;
  int nz = 0;
  for (const auto& [name, v] : base.features) {
    const auto it = data.features.find(name);
    if (it == data.features.end() ||
        std::find(excluded.begin(), excluded.end(), name) != excluded.end())
      continue;
    b.push_back(base.mesh.vertices[v].head<2>());
    o.push_back(it->second.head_mm.head<2>());
    if (it->second.has_depth) zb += base.mesh.vertices[v].z(), zo += it->second.head_mm.z(), ++nz;
  }
  Alignment a = align_by_boundary(data);
  if (b.size() < 3) return a;
  const Spread sb = spread_of(b), so = spread_of(o);
  if (sb.rms.minCoeff() < 1e-6 || so.rms.minCoeff() < 1e-6) return a;
  a.scale.head<2>() = so.rms.cwiseQuotient(sb.rms);  // seed 002 §3.3.1: x, y separately
  a.translation.head<2>() = so.centre - a.scale.head<2>().cwiseProduct(sb.centre);
  a.scale.z() = a.scale.x();  // z like x (seed 002, after Fleming and Dobbs)
  if (nz > 0) {
    a.translation.z() = (zo - a.scale.z() * zb) / nz;
  } else {  // depth from the profile at the centre of the observed heights
    const double y = 0.5 * (data.y_top + data.y_bottom);
    const double base_y = (y - a.translation.y()) / a.scale.y();
    const auto z = profile_z_at(data, y);
    if (z) a.translation.z() = *z - a.scale.z() * generic_contour(base_y, 0.0).y();
  }
  return a;
}

AdaptResult adapt(const BaseMesh& base, const StereoData& data, const AdaptOptions& options) {
  options.check();
  AdaptResult r;
  r.warnings = data.warnings;
  detail::AlignedTargets at = detail::align_and_target(base, data, options, &r.warnings);
  r.alignment = at.alignment;
  r.targets = std::move(at.targets);
  const std::vector<Eigen::Vector3d>& aligned = at.aligned;
  const int n_landmarks = static_cast<int>(r.targets.vertices.size());
  if (n_landmarks < 3)
    throw std::invalid_argument("cannot reconstruct: only " + std::to_string(n_landmarks) +
                                " base vertices have 3D data (need the silhouette and profile)");
  if (options.k > n_landmarks)
    throw std::invalid_argument("AdaptOptions: k = " + std::to_string(options.k) +
                                " exceeds the landmark count " + std::to_string(n_landmarks));
  std::vector<Eigen::Vector3d> moved =
      options.method == AdaptMethod::Nnwa
          ? detail::move_by_nnwa(aligned, r.targets, options.k)
          : detail::move_by_interpolation(base, aligned, r.targets, options.k);
  const auto& adjacency = base.neighbours.size() == base.mesh.vertices.size()
                              ? base.neighbours
                              : detail::vertex_adjacency(base.mesh);
  detail::blend_near_features(adjacency, aligned, r.targets, options, moved);
  const detail::Smoothing sm =
      detail::smooth_if_rough(adjacency, aligned, r.targets, options, moved);
  r.roughness_mm = sm.roughness_mm;
  r.smoothed_share = sm.share;
  r.mesh = base.mesh;
  r.mesh.vertices = std::move(moved);
  const auto [fixed, remaining] =
      detail::remove_folds(adjacency, aligned, r.targets, options.max_fold_passes, r.mesh);
  r.folds_fixed = fixed;
  r.folds_remaining = remaining;
  if (remaining > 0)
    r.warnings.push_back(std::to_string(remaining) + " triangles stay flipped after relaxation");
  // Real pairs: a feature the front photo places beyond its slice's side (a brow tail at the
  // temple of a turned head) stands out as a fin the front camera sees from behind, and the
  // side photo then paints it (white flashes beside the eye at -15 deg); a slice the silhouette
  // gives no width (ear and jaw heights) keeps the base's, which can reach past the real cheek,
  // and a view turned toward it then shows the front photo's background there.
  if (options.open_fins) r.fins_opened = detail::open_slice_fins(base, r.mesh);
  if (options.inside_silhouette)
    r.clamped_to_silhouette = clamp_to_silhouette(data, r.mesh, options.silhouette_margin_mm);
  for (const auto& [name, v] : base.features) r.landmarks[name] = r.mesh.vertices[v];
  return r;
}

}  // namespace orthoface::model
