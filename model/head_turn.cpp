#include "model/head_turn.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "model/base_mesh.h"

namespace orthoface::model {
namespace {

// Front points whose definition is the generic head's (the network's nose wings sit at the
// nostril's base, the base mesh's at the wing's outermost point: left out).
bool usable(const std::string& name) { return name != "alar_left" && name != "alar_right"; }

double median_of(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

std::optional<HeadTurn> estimate_head_turn(const vision::FaceObservation& observation,
                                           const capture::RigCalibration& rig,
                                           const StereoData& data) {
  const auto generic = generic_landmarks();
  struct Sample {
    double x;           // front point, head-frame x (mm) on the plane z = 0
    Eigen::Vector3d g;  // generic landmark
  };
  std::vector<Sample> samples;
  for (const auto& [name, f] : observation.front_trained) {
    if (!std::isfinite(f.px.x) || !std::isfinite(f.px.y))
      throw std::invalid_argument("head turn: front point '" + name + "' is not finite");
    const auto g = generic.find(name);
    if (g == generic.end() || !usable(name)) continue;
    samples.push_back({point_at_depth(rig.front, {f.px.x, f.px.y}, 0.0).x(), g->second});
  }
  // x = c + a x_g + b z_g with a = s cos t, b = s sin t (weak perspective, yaw only).
  auto fit = [](const std::vector<Sample>& s) {
    Eigen::MatrixXd m(s.size(), 3);
    Eigen::VectorXd x(s.size());
    for (size_t i = 0; i < s.size(); ++i) {
      m.row(long(i)) << 1, s[i].g.x(), s[i].g.z();
      x(long(i)) = s[i].x;
    }
    return Eigen::Vector3d(m.colPivHouseholderQr().solve(x));
  };
  constexpr size_t kMinPoints = 6;
  if (samples.size() < kMinPoints) return std::nullopt;
  Eigen::Vector3d k = fit(samples);
  auto residual = [&](const Sample& s) {
    return std::abs(s.x - (k(0) + k(1) * s.g.x() + k(2) * s.g.z()));
  };
  std::vector<double> r;
  for (const Sample& s : samples) r.push_back(residual(s));
  const double limit = std::max(1.0, 3 * median_of(r));
  std::vector<Sample> kept;
  for (const Sample& s : samples)
    if (residual(s) <= limit) kept.push_back(s);
  if (kept.size() < kMinPoints) return std::nullopt;
  k = fit(kept);
  HeadTurn turn;
  turn.yaw_rad = std::atan2(k(2), k(1));
  turn.scale = std::hypot(k(1), k(2));
  if (!(turn.scale > 0.5 && turn.scale < 2)) return std::nullopt;
  turn.points = int(kept.size());
  double ss = 0;
  for (const Sample& s : kept) ss += residual(s) * residual(s);
  turn.residual_mm = std::sqrt(ss / double(kept.size()));
  // The axis depth: where the features the side photo placed in depth say the generic origin is.
  const double c = std::cos(turn.yaw_rad), sn = std::sin(turn.yaw_rad);
  std::vector<double> az;
  for (const auto& [name, p] : data.features) {
    const auto g = generic.find(name);
    if (!p.has_depth || g == generic.end()) continue;
    az.push_back(p.head_mm.z() - turn.scale * (-g->second.x() * sn + g->second.z() * c));
  }
  if (az.empty()) return std::nullopt;
  turn.axis = {k(0), 0.0, median_of(az)};
  return turn;
}

Eigen::Vector3d turned(const Eigen::Vector3d& p, const HeadTurn& turn) {
  const double c = std::cos(turn.yaw_rad), s = std::sin(turn.yaw_rad);
  const Eigen::Vector3d r = p - turn.axis;
  return {turn.axis.x() + r.x() * c + r.z() * s, p.y(), turn.axis.z() - r.x() * s + r.z() * c};
}

StereoData facing_front(const StereoData& data, const HeadTurn& turn) {
  const double c = std::cos(turn.yaw_rad), s = std::sin(turn.yaw_rad);
  const auto generic = generic_landmarks();
  HeadTurn back = turn;  // R_y(-t) about the same axis undoes turned()
  back.yaw_rad = -turn.yaw_rad;
  StereoData out = data;
  for (auto& [name, p] : out.features) {
    if (p.has_depth) {
      p.head_mm = turned(p.head_mm, back);
      continue;
    }
    const auto g = generic.find(name);  // depth unknown: the generic head's, turned
    if (g == generic.end()) continue;
    Eigen::Vector3d q = p.head_mm;
    q.z() = turn.axis.z() + turn.scale * (-g->second.x() * s + g->second.z() * c);
    p.head_mm.x() = turned(q, back).x();
  }
  out.centre_point.x() = turn.axis.x();
  // The silhouette keeps its width: a head turned by t is foreshortened across its width and
  // shows its depth in exchange (an ellipse of half-width a and half-depth b shows
  // sqrt(a^2 cos^2 t + b^2 sin^2 t)), and on sim heads turned by 10 and 20 degrees widening it by
  // 1 / cos t put the model further from the truth than keeping it (docs/views_accuracy.md).
  for (Eigen::Vector2d& p : out.profile)  // (z, y)
    p.x() = turn.axis.z() + (p.x() - turn.axis.z()) / c;
  return out;
}

void turn_mesh(mesh::TriMesh& mesh, const HeadTurn& turn) {
  for (Eigen::Vector3d& v : mesh.vertices) v = turned(v, turn);
}

}  // namespace orthoface::model
