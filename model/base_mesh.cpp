#include "model/base_mesh.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace orthoface::model {
namespace {

// The generic face is written as a few smooth functions of height with average adult
// proportions (head frame, mm): a superellipse contour per height from the silhouette extreme
// to the centre line, plus bumps for nose and lips and dips for the eye sockets.
struct Knot {
  double y, value;
};

double piecewise(const std::vector<Knot>& knots, double y) {  // knots sorted by y, descending
  if (y >= knots.front().y) return knots.front().value;
  if (y <= knots.back().y) return knots.back().value;
  for (size_t i = 1; i < knots.size(); ++i) {
    if (y < knots[i].y) continue;
    const double t = (y - knots[i].y) / (knots[i - 1].y - knots[i].y);
    const double s = t * t * (3 - 2 * t);  // smoothstep: no kinks in the generic profile
    return knots[i].value + (knots[i - 1].value - knots[i].value) * s;
  }
  return knots.back().value;
}

const std::vector<Knot>& half_width_knots() {
  static const std::vector<Knot> k = {{82, 58}, {60, 68}, {38, 71}, {24, 72}, {0, 72},
                                      {-10, 70}, {-24, 67}, {-40, 61}, {-55, 53}, {-66, 44},
                                      {-74, 34}, {-80, 22}};
  return k;
}
const std::vector<Knot>& silhouette_depth_knots() {
  static const std::vector<Knot> k = {{82, 5}, {0, 5}, {-40, 15}, {-66, 40}, {-80, 55}};
  return k;
}
const std::vector<Knot>& face_depth_knots() {  // midline depth without nose and lips
  static const std::vector<Knot> k = {{82, 80}, {60, 93}, {38, 99}, {30, 95}, {24, 95},
                                      {-10, 96}, {-24, 97}, {-40, 97}, {-55, 95}, {-66, 96},
                                      {-74, 89}, {-80, 76}};
  return k;
}
const std::vector<Knot>& nose_height_knots() {
  static const std::vector<Knot> k = {{30, 0}, {24, 3}, {10, 11}, {0, 18}, {-10, 24},
                                      {-18, 12}, {-24, 3}, {-28, 0}};
  return k;
}
const std::vector<Knot>& nose_width_knots() {
  static const std::vector<Knot> k = {{30, 6}, {10, 7}, {-10, 9}, {-18, 14}, {-28, 14}};
  return k;
}

constexpr double kSuperellipse = 2.6;

struct GenericLandmark {
  const char* name;
  const char* slice;
  double x;
};

// Characteristic heights (top to bottom) and the landmarks that sit on them.
const std::vector<std::pair<std::string, double>>& characteristic_heights() {
  static const std::vector<std::pair<std::string, double>> h = {
      {"forehead_top", 82}, {"brow", 38},      {"nose_bridge", 30}, {"eye", 24},
      {"nose_tip", -10},    {"alar", -18},     {"subnasale", -24},  {"lip_upper", -33},
      {"mouth", -40},       {"lip_lower", -47}, {"chin", -66},      {"chin_bottom", -80}};
  return h;
}

const std::vector<GenericLandmark>& generic_landmarks() {
  static const std::vector<GenericLandmark> l = {
      {"forehead_top", "forehead_top", 0}, {"brow_left_inner", "brow", 18},
      {"brow_left_center", "brow", 35},    {"brow_left_outer", "brow", 52},
      {"brow_right_inner", "brow", -18},   {"brow_right_center", "brow", -35},
      {"brow_right_outer", "brow", -52},   {"nose_bridge", "nose_bridge", 0},
      {"eye_left_inner", "eye", 16},       {"eye_left_center", "eye", 32},
      {"eye_left_outer", "eye", 46},       {"eye_right_inner", "eye", -16},
      {"eye_right_center", "eye", -32},    {"eye_right_outer", "eye", -46},
      {"nose_tip", "nose_tip", 0},         {"cheek_left", "nose_tip", 1e9},
      {"cheek_right", "nose_tip", -1e9},   {"alar_left", "alar", 17},
      {"alar_right", "alar", -17},         {"subnasale", "subnasale", 0},
      {"lip_upper", "lip_upper", 0},       {"mouth_left", "mouth", 25},
      {"mouth_right", "mouth", -25},       {"lip_lower", "lip_lower", 0},
      {"chin", "chin", 0},                 {"chin_bottom", "chin_bottom", 0}};
  return l;
}

std::vector<std::pair<std::string, double>> slice_plan(double max_gap) {
  const auto& h = characteristic_heights();
  std::vector<std::pair<std::string, double>> plan;
  for (size_t i = 0; i < h.size(); ++i) {
    plan.push_back(h[i]);
    if (i + 1 == h.size()) break;
    const double gap = h[i].second - h[i + 1].second;
    const int extra = static_cast<int>(std::ceil(gap / max_gap)) - 1;
    for (int e = 1; e <= extra; ++e)
      plan.push_back({"", h[i].second - gap * e / (extra + 1)});
  }
  return plan;
}

}  // namespace

void BaseMeshOptions::check() const {
  if (vertices_per_slice < 9 || vertices_per_slice % 2 == 0 || vertices_per_slice > 401)
    throw std::invalid_argument("BaseMeshOptions: vertices_per_slice must be odd in [9, 401], got " +
                                std::to_string(vertices_per_slice));
  if (!(max_slice_gap_mm >= 1.0 && max_slice_gap_mm <= 100.0))
    throw std::invalid_argument("BaseMeshOptions: max_slice_gap_mm must be in [1, 100], got " +
                                std::to_string(max_slice_gap_mm));
}

double generic_half_width(double y_mm) { return piecewise(half_width_knots(), y_mm); }

double generic_face_depth(double x, double y) {
  const double w = generic_half_width(y);
  const double ze = piecewise(silhouette_depth_knots(), y);
  const double zc = piecewise(face_depth_knots(), y);
  const double r = std::min(1.0, std::abs(x) / w);
  const double shape = std::pow(1.0 - std::pow(r, kSuperellipse), 1.0 / kSuperellipse);
  const double nose_w = piecewise(nose_width_knots(), y);
  const double nose = piecewise(nose_height_knots(), y) * std::exp(-std::pow(x / nose_w, 2));
  const double lips = (6.0 * std::exp(-std::pow((y + 33) / 4.0, 2)) +
                       5.0 * std::exp(-std::pow((y + 47) / 4.0, 2))) *
                      std::exp(-std::pow(x / 16.0, 2));
  const double eyes = 8.0 * std::exp(-std::pow((std::abs(x) - 32) / 12.0, 2) -
                                     std::pow((y - 24) / 8.0, 2));
  // Features fade out toward the silhouette so the extremes keep a vertical tangent.
  return ze + (zc - ze) * shape + (nose + lips - eyes) * shape;
}

BaseMesh base_mesh(const BaseMeshOptions& options) {
  options.check();
  const auto plan = slice_plan(options.max_slice_gap_mm);
  const int n = options.vertices_per_slice;
  const double y_top = plan.front().second, y_bottom = plan.back().second;
  BaseMesh b;
  for (size_t s = 0; s < plan.size(); ++s) {
    const double y = plan[s].second;
    const double w = generic_half_width(y);
    std::vector<int> ids;
    for (int i = 0; i < n; ++i) {
      const double phi = M_PI * (static_cast<double>(i) / (n - 1) - 0.5);
      const double x = (i == (n - 1) / 2) ? 0.0 : w * std::sin(phi);
      ids.push_back(static_cast<int>(b.mesh.vertices.size()));
      b.mesh.vertices.emplace_back(x, y, generic_face_depth(x, y));
      b.mesh.uvs.emplace_back(static_cast<double>(i) / (n - 1),
                              (y - y_bottom) / (y_top - y_bottom));
      const bool boundary = i == 0 || i == n - 1 || i == (n - 1) / 2;
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
  for (const GenericLandmark& l : generic_landmarks()) {
    const auto it = std::find(b.slice_names.begin(), b.slice_names.end(), l.slice);
    const std::vector<int>& ids = b.slices[it - b.slice_names.begin()];
    int best = ids.front();
    for (int id : ids)
      if (std::abs(b.mesh.vertices[id].x() - l.x) < std::abs(b.mesh.vertices[best].x() - l.x))
        best = id;
    b.features[l.name] = best;
    b.groups[best] = VertexGroup::Feature;
  }
  return b;
}

}  // namespace orthoface::model
