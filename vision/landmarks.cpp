#include "vision/landmarks.h"

#include <algorithm>
#include <stdexcept>

namespace orthoface::vision {

bool is_landmark_name(std::string_view name) {
  return std::find(kLandmarkNames.begin(), kLandmarkNames.end(), name) != kLandmarkNames.end();
}

std::string mirrored_name(std::string_view name) {
  if (!is_landmark_name(name))
    throw std::invalid_argument("mirrored_name: unknown landmark '" + std::string(name) + "'");
  std::string s(name);
  if (auto p = s.find("_left"); p != std::string::npos) return s.replace(p, 5, "_right");
  if (auto p = s.find("_right"); p != std::string::npos) return s.replace(p, 6, "_left");
  return s;
}

}  // namespace orthoface::vision
