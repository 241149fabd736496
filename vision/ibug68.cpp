#include "vision/ibug68.h"

#include <cmath>
#include <stdexcept>

#include "vision/landmarks.h"

namespace orthoface::vision {
namespace {

// The chin (its most forward point, seed 004's profile chin) lies this share of the way from
// the lower lip down to the chin's bottom (sim heads: 0.84).
constexpr double kChinShare = 0.8;

bool finite(const cv::Point2d& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

}  // namespace

int ibug68_index(std::string_view name) {
  if (!is_landmark_name(name))
    throw std::invalid_argument("ibug68_index: '" + std::string(name) +
                                "' is not a landmark name (vision/landmarks.h)");
  for (const auto& [n, k] : kIbug68Landmarks)
    if (n == name) return k;
  return -1;
}

std::map<std::string, cv::Point2d> named_from_ibug68(const Ibug68& points) {
  for (int k = 0; k < kIbug68Count; ++k)
    if (points[k] && !finite(*points[k]))
      throw std::invalid_argument("named_from_ibug68: point " + std::to_string(k) +
                                  " is not finite");
  std::map<std::string, cv::Point2d> out;
  for (const auto& [name, k] : kIbug68Landmarks)
    if (points[k]) out[std::string(name)] = *points[k];
  // Eye centres: the mean of each eye's six contour points (36-41 image left, 42-47 image right).
  for (const auto& [name, first] : {std::pair<const char*, int>{"eye_right_center", 36},
                                    std::pair<const char*, int>{"eye_left_center", 42}}) {
    cv::Point2d sum(0, 0);
    int known = 0;
    for (int k = first; k < first + 6; ++k)
      if (points[k]) sum += *points[k], ++known;
    if (known == 6) out[name] = sum / 6.0;
  }
  if (points[57] && points[8]) out["chin"] = *points[57] + kChinShare * (*points[8] - *points[57]);
  return out;
}

Ibug68 ibug68_from_named(const std::map<std::string, Feature2d>& features) {
  Ibug68 out;
  for (const auto& [name, k] : kIbug68Landmarks) {
    const auto it = features.find(std::string(name));
    if (it == features.end()) continue;
    if (!finite(it->second.px))
      throw std::invalid_argument("ibug68_from_named: feature " + std::string(name) +
                                  " is not finite");
    out[k] = it->second.px;
  }
  return out;
}

}  // namespace orthoface::vision
