#include "vision/registration.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "vision/landmarks.h"

namespace orthoface::vision {

RowMap side_row_map(const FaceObservation& obs) {
  std::vector<std::pair<double, double>> all, independent;
  for (const auto& [name, f] : obs.front.features) {
    if (!is_landmark_name(name) || mirrored_name(name) != name) continue;
    const auto it = obs.side.features.find(name);
    if (it == obs.side.features.end()) continue;
    all.push_back({f.px.y, it->second.px.y});
    // A front row copied from the profile (the filters' midline) registers nothing; a side
    // feature placed by the position model is a guess.
    const bool copied = f.method.find("profile-row") != std::string::npos;
    const bool guessed = it->second.method.find("position-model") != std::string::npos;
    if (!copied && !guessed) independent.push_back({f.px.y, it->second.px.y});
  }
  auto fit = [](const std::vector<std::pair<double, double>>& rows) {
    RowMap m;
    m.pairs = int(rows.size());
    if (rows.empty()) return m;
    double mf = 0, ms = 0;
    for (auto [f, s] : rows) mf += f / rows.size(), ms += s / rows.size();
    double sff = 0, sfs = 0;
    for (auto [f, s] : rows) sff += (f - mf) * (f - mf), sfs += (f - mf) * (s - ms);
    m.a = (rows.size() >= 2 && sff > 400.0) ? sfs / sff : 1.0;  // spread >= ~20 px
    m.b = ms - m.a * mf;
    return m;
  };
  if (independent.size() < 3) return fit(all);
  // Least median of squares over the lines through two pairs (scale within 0.8..1.25: the same
  // kind of camera at a similar distance), then least squares on the pairs within 3 px of it.
  double best = INFINITY;
  RowMap line;
  for (size_t i = 0; i < independent.size(); ++i)
    for (size_t j = i + 1; j < independent.size(); ++j) {
      const auto [f0, s0] = independent[i];
      const auto [f1, s1] = independent[j];
      if (std::abs(f1 - f0) < 20) continue;
      const double a = (s1 - s0) / (f1 - f0), b = s0 - a * f0;
      if (!(a > 0.8 && a < 1.25)) continue;
      std::vector<double> res;
      for (auto [f, s] : independent) res.push_back(std::abs(s - (a * f + b)));
      std::nth_element(res.begin(), res.begin() + res.size() / 2, res.end());
      if (res[res.size() / 2] < best) best = res[res.size() / 2], line.a = a, line.b = b;
    }
  if (!std::isfinite(best)) return fit(all);
  std::vector<std::pair<double, double>> inliers;
  for (auto [f, s] : independent)
    if (std::abs(s - (line.a * f + line.b)) < 3.0) inliers.push_back({f, s});
  RowMap m = inliers.size() >= 2 ? fit(inliers) : line;
  m.pairs = int(inliers.size());
  m.independent = true;
  return m;
}

}  // namespace orthoface::vision
