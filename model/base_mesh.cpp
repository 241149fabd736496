#include "model/base_mesh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "model/generic_head.h"

namespace orthoface::model {
namespace {

// Landmarks whose heights become slices (seed 004 §5: brow, eyes, nose tip, subnasale, mouth,
// chin ...). Brows, eyes and mouth corners stand for their row.
constexpr const char* kCharacteristic[] = {
    "forehead_top", "brow_left_center", "nose_bridge", "eye_left_center",
    "nose_tip",     "alar_left",        "subnasale",   "lip_upper",
    "mouth_left",   "lip_lower",        "chin",        "chin_bottom"};

constexpr double kMaxExtrapolationMm = 40;

std::vector<std::pair<std::string, double>> slice_plan(const BaseMeshOptions& o) {
  const double max_gap = o.max_slice_gap_mm;
  const auto l = generic_landmarks();
  std::vector<std::pair<std::string, double>> h;
  for (const char* name : kCharacteristic) h.push_back({name, l.at(name).y()});
  if (o.margin_above_mm > 0) h.push_back({"", l.at("forehead_top").y() + o.margin_above_mm});
  if (o.margin_below_mm > 0) h.push_back({"", l.at("chin_bottom").y() - o.margin_below_mm});
  std::sort(h.begin(), h.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::vector<std::pair<std::string, double>> plan;
  for (size_t i = 0; i < h.size(); ++i) {
    plan.push_back(h[i]);
    if (i + 1 == h.size()) break;
    const double gap = h[i].second - h[i + 1].second;
    const int extra = static_cast<int>(std::ceil(gap / max_gap)) - 1;
    for (int e = 1; e <= extra; ++e) plan.push_back({"", h[i].second - gap * e / (extra + 1)});
  }
  return plan;
}

}  // namespace

void BaseMeshOptions::check() const {
  if (vertices_per_slice < 9 || vertices_per_slice % 2 == 0 || vertices_per_slice > 401)
    throw std::invalid_argument(
        "BaseMeshOptions: vertices_per_slice must be odd in [9, 401], got " +
        std::to_string(vertices_per_slice));
  if (!(max_slice_gap_mm >= 1.0 && max_slice_gap_mm <= 200.0))
    throw std::invalid_argument("BaseMeshOptions: max_slice_gap_mm must be in [1, 200], got " +
                                std::to_string(max_slice_gap_mm));
  for (const auto& [name, margin] : {std::pair{"margin_above_mm", margin_above_mm},
                                     std::pair{"margin_below_mm", margin_below_mm}})
    if (!(margin >= 0 && margin <= kMaxExtrapolationMm))
      throw std::invalid_argument(std::string("BaseMeshOptions: ") + name + " must be in [0, " +
                                  std::to_string(int(kMaxExtrapolationMm)) + "], got " +
                                  std::to_string(margin));
}

namespace {

// The sampled contour at table row `row` (fractional, inside the table), ray |angle|.
Eigen::Vector2d sampled_contour(double row, double ray) {
  const detail::GenericHead& g = detail::generic_head();
  const int r0 = std::min(static_cast<int>(row), g.rows - 2);
  const int a0 = std::min(static_cast<int>(ray), g.half_rays - 2);
  const double tr = row - r0, ta = ray - a0;
  auto at = [&g](int r, int a) { return Eigen::Vector2d(g.at(r, a)[0], g.at(r, a)[1]); };
  return (1 - tr) * ((1 - ta) * at(r0, a0) + ta * at(r0, a0 + 1)) +
         tr * ((1 - ta) * at(r0 + 1, a0) + ta * at(r0 + 1, a0 + 1));
}

}  // namespace

Eigen::Vector2d generic_contour(double y, double angle) {
  const detail::GenericHead& g = detail::generic_head();
  // Bilinear in (row, ray) over the sampled table; the head is mirror symmetric in x.
  const double row_mm = (g.top - g.bottom) / (g.rows - 1);
  const double row =
      (g.top - std::clamp(y, g.bottom - kMaxExtrapolationMm, g.top + kMaxExtrapolationMm)) / row_mm;
  const double ray = std::clamp(std::abs(angle) / (M_PI / 2), 0.0, 1.0) * (g.half_rays - 1);
  Eigen::Vector2d p;
  if (row < 0 || row > g.rows - 1) {  // linear continuation of the end row's slope
    const double end = row < 0 ? 0 : g.rows - 1, inner = row < 0 ? 1 : g.rows - 2;
    const Eigen::Vector2d e = sampled_contour(end, ray);
    p = e + std::abs(row - end) * (e - sampled_contour(inner, ray));
    p.x() = std::max(p.x(), 0.0);
  } else {
    p = sampled_contour(row, ray);
  }
  return {angle < 0 ? -p.x() : p.x(), p.y()};
}

double generic_half_width(double y_mm) { return generic_contour(y_mm, M_PI / 2).x(); }

std::map<std::string, Eigen::Vector3d> generic_landmarks() {
  std::map<std::string, Eigen::Vector3d> out;
  for (const auto& [name, p] : detail::generic_head().landmarks) out[name] = p;
  return out;
}

BaseMesh base_mesh(const BaseMeshOptions& options) {
  options.check();
  const auto plan = slice_plan(options);
  const int n = options.vertices_per_slice, mid = (n - 1) / 2;
  const double y_top = plan.front().second, y_bottom = plan.back().second;
  BaseMesh b;
  for (size_t s = 0; s < plan.size(); ++s) {
    const double y = plan[s].second;
    std::vector<int> ids;
    for (int i = 0; i < n; ++i) {
      const double phi = M_PI * (static_cast<double>(i) / (n - 1) - 0.5);
      const Eigen::Vector2d xz = generic_contour(y, phi);
      ids.push_back(static_cast<int>(b.mesh.vertices.size()));
      b.mesh.vertices.emplace_back(i == mid ? 0.0 : xz.x(), y, xz.y());
      b.mesh.uvs.emplace_back(static_cast<double>(i) / (n - 1),
                              (y - y_bottom) / (y_top - y_bottom));
      const bool boundary = i == 0 || i == n - 1 || i == mid;
      b.groups.push_back(boundary ? VertexGroup::Boundary : VertexGroup::NonFeature);
      b.slice_of_vertex.push_back(static_cast<int>(s));
    }
    b.slices.push_back(ids);
    b.slice_heights.push_back(y);
    b.slice_names.push_back(plan[s].first);
  }
  // Quads between consecutive slices, counter-clockwise seen from the front (+z).
  for (size_t s = 0; s + 1 < b.slices.size(); ++s)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = b.slices[s][i], bb = b.slices[s][i + 1];
      const int c = b.slices[s + 1][i], d = b.slices[s + 1][i + 1];
      b.mesh.triangles.push_back({a, c, d});
      b.mesh.triangles.push_back({a, d, bb});
    }
  b.neighbours.assign(b.mesh.vertices.size(), {});
  for (const auto& f : b.mesh.triangles)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        auto& n = b.neighbours[f[i]];
        if (i != j && std::find(n.begin(), n.end(), f[j]) == n.end()) n.push_back(f[j]);
      }
  // Feature vertices: the vertex nearest each generic landmark (ears are outside the face),
  // slid along its slice to the landmark's contour angle: exactly onto the landmark when the
  // slice is at its height. A feature vertex left where the evenly spaced rays put it (up to
  // half a ray step off, 3 mm at the eyes) would carry that offset into every adaptation as a
  // displacement the face does not have. Boundary vertices stay (midline features lie on them).
  for (const auto& [name, p] : generic_landmarks()) {
    if (name.rfind("ear_", 0) == 0) continue;
    int best = 0;
    for (int v = 0; v < static_cast<int>(b.mesh.vertices.size()); ++v)
      if ((b.mesh.vertices[v] - p).squaredNorm() < (b.mesh.vertices[best] - p).squaredNorm())
        best = v;
    b.features[name] = best;
    if (b.groups[best] == VertexGroup::NonFeature) {
      const double phi = std::atan2(p.x(), p.z()), y = b.mesh.vertices[best].y();
      const Eigen::Vector2d xz = generic_contour(y, phi);
      b.mesh.vertices[best] = {xz.x(), y, xz.y()};
      b.mesh.uvs[best].x() = phi / M_PI + 0.5;  // u = contour angle, as for the others
    }
    b.groups[best] = VertexGroup::Feature;
  }
  return b;
}

}  // namespace orthoface::model
