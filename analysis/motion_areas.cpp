#include "analysis/motion_areas.h"

#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "analysis/geodesics.h"
#include "analysis/mpeg4_names.h"
#include "io/json_text.h"
#include "vision/landmarks.h"

namespace orthoface::analysis {

Spherical to_spherical(const Eigen::Vector3d& p) {
  Spherical s;
  s.rho = p.norm();  // seed 001 eq. 1
  if (s.rho <= 0.0) return s;
  s.phi = std::acos(std::clamp(p.z() / s.rho, -1.0, 1.0));  // eq. 2
  s.theta = std::atan2(p.y(), p.x());                       // eq. 3 (see header)
  return s;
}

double haversine_distance(const Spherical& a, const Spherical& b) {
  // Seed 001 eq. 7 takes phi as the latitude, but eq. 2 defines phi as the polar angle from
  // +z, so the latitude is pi/2 - phi and its cosine is sin(phi). Using eq. 7 literally gives
  // a wrong great-circle angle (2.18 instead of 1.98 for Table I's A, B).
  const double dphi = b.phi - a.phi, dtheta = b.theta - a.theta;
  const double h = std::sin(0.5 * dphi) * std::sin(0.5 * dphi) + std::sin(a.phi) * std::sin(b.phi) *
                                                                     std::sin(0.5 * dtheta) *
                                                                     std::sin(0.5 * dtheta);
  const double c = 2.0 * std::atan2(std::sqrt(h), std::sqrt(std::max(0.0, 1.0 - h)));  // eq. 8
  return a.rho * c;                                                                    // eq. 9
}

void SegmentationOptions::check() const {
  if (!centre.allFinite()) throw std::invalid_argument("SegmentationOptions: centre not finite");
  if (!(falloff > 0.0) || !std::isfinite(falloff))
    throw std::invalid_argument("SegmentationOptions: falloff must be > 0, got " +
                                std::to_string(falloff));
}

namespace {

void check_points(const std::vector<FeaturePoint>& points) {
  if (points.empty()) throw std::invalid_argument("segment_by_feature_points: no feature points");
  std::set<std::string> names;
  for (const auto& p : points) {
    if (!p.position.allFinite())
      throw std::invalid_argument("segment_by_feature_points: point '" + p.name +
                                  "' is not finite");
    if (!names.insert(p.name).second)
      throw std::invalid_argument("segment_by_feature_points: point '" + p.name +
                                  "' appears twice");
  }
}

// Gaussian falloff of the geodesic distance from the vertex nearest each point, normalised
// over the points at each vertex.
std::vector<std::vector<double>> smooth_weights(const mesh::TriMesh& mesh,
                                                const std::vector<FeaturePoint>& points,
                                                double sigma) {
  const size_t nv = mesh.vertices.size();
  std::vector<std::vector<double>> w(points.size(), std::vector<double>(nv, 0.0));
  GeodesicOptions go;
  go.max_distance = 3.0 * sigma;
  for (size_t p = 0; p < points.size(); ++p) {
    int nearest = 0;
    for (size_t v = 1; v < nv; ++v)
      if ((mesh.vertices[v] - points[p].position).squaredNorm() <
          (mesh.vertices[nearest] - points[p].position).squaredNorm())
        nearest = int(v);
    const auto d = geodesic_distances(mesh, {nearest}, go);
    for (size_t v = 0; v < nv; ++v)
      if (std::isfinite(d[v])) w[p][v] = std::exp(-0.5 * d[v] * d[v] / (sigma * sigma));
  }
  for (size_t v = 0; v < nv; ++v) {
    double sum = 0.0;
    for (const auto& row : w) sum += row[v];
    if (sum > 0.0)
      for (auto& row : w) row[v] /= sum;
  }
  return w;
}

}  // namespace

Segmentation segment_by_feature_points(const mesh::TriMesh& mesh,
                                       const std::vector<FeaturePoint>& points,
                                       const SegmentationOptions& options) {
  mesh::check_mesh(mesh, "segment_by_feature_points");
  options.check();
  check_points(points);
  std::vector<Spherical> fp;
  for (const auto& p : points) fp.push_back(to_spherical(p.position - options.centre));
  Segmentation s;
  s.label.resize(mesh.vertices.size());
  s.count.assign(points.size(), 0);
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const Spherical sv = to_spherical(mesh.vertices[v] - options.centre);
    int best = 0;
    double best_d = std::numeric_limits<double>::infinity();
    for (size_t p = 0; p < fp.size(); ++p) {
      const double d = haversine_distance(sv, fp[p]);
      if (d < best_d) best_d = d, best = int(p);
    }
    s.label[v] = best;
    ++s.count[best];
  }
  for (int c : s.count) s.percent.push_back(100.0 * c / double(mesh.vertices.size()));
  if (options.smooth_weights) s.weights = smooth_weights(mesh, points, options.falloff);
  return s;
}

namespace {

// The point `name` at `field` ("9.3", "points[2].position") of the file `path`.
FeaturePoint parse_point(const std::string& path, const std::string& name, const std::string& field,
                         const nlohmann::json& pos) {
  if (!pos.is_array() || pos.size() != 3)
    throw std::runtime_error(path + ": " + io::json_type_error(field, "a position [x, y, z]", pos));
  Eigen::Vector3d p;
  try {
    for (int k = 0; k < 3; ++k)
      p[k] = io::json_number(pos[k], field + "[" + std::to_string(k) + "]");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return {name, p};
}

}  // namespace

std::vector<FeaturePoint> read_feature_points(const std::string& path, bool allow_any_names) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open feature-point file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not valid JSON (" + io::json_error_text(e) + ")");
  }
  std::vector<FeaturePoint> out;
  const char* list_key = j.contains("feature_points") ? "feature_points" : "points";
  if (j.is_object() && j.contains(list_key) && j[list_key].is_array()) {
    const nlohmann::json& list = j[list_key];
    for (size_t i = 0; i < list.size(); ++i) {
      const nlohmann::json& e = list[i];
      const std::string at = std::string(list_key) + "[" + std::to_string(i) + "]";
      if (!e.is_object() || !e.contains("name") || !e.contains("position"))
        throw std::runtime_error(path + ": " + at + ": expected an object with \"name\" and " +
                                 "\"position\", got " + io::json_type_name(e));
      if (!e["name"].is_string())
        throw std::runtime_error(path + ": " +
                                 io::json_type_error(at + ".name", "a string", e["name"]));
      out.push_back(
          parse_point(path, e["name"].get<std::string>(), at + ".position", e["position"]));
    }
  } else if (j.is_object()) {
    for (const auto& [name, pos] : j.items()) out.push_back(parse_point(path, name, name, pos));
  } else {
    throw std::runtime_error(path + ": " +
                             io::json_type_error("top level", "an object of feature points", j));
  }
  if (out.empty()) throw std::runtime_error(path + ": no feature points");
  std::string unknown;
  for (const auto& p : out)
    if (!allow_any_names && !is_feature_point_name(p.name) && !vision::is_landmark_name(p.name))
      unknown += (unknown.empty() ? "" : ", ") + p.name;
  if (!unknown.empty())
    throw std::runtime_error(
        path + ": unknown feature point name(s): " + unknown +
        " (expected MPEG-4 names like 9.3, the helpers nasion and sulcus, or landmark names "
        "like nose_tip)");
  return out;
}

}  // namespace orthoface::analysis
