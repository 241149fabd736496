#include "vision/profile_mask.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace orthoface::vision {

cv::Mat profile_mask(const ViewObservation& side, bool faces_left) {
  if (side.width <= 0 || side.height <= 0)
    throw std::invalid_argument("profile mask: the side view has no image size");
  if (side.boundary.size() < 2)
    throw std::invalid_argument("profile mask: the side view has no profile (" +
                                std::to_string(side.boundary.size()) + " points)");
  // Per row the most frontal profile crossing (a hooked nose crosses a row more than once).
  std::vector<double> front_x(side.height, std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k + 1 < side.boundary.size(); ++k) {
    const cv::Point2d a = side.boundary[k], b = side.boundary[k + 1];
    const int r0 = std::max(0, int(std::ceil(std::min(a.y, b.y) - 0.5)));
    const int r1 = std::min(side.height - 1, int(std::floor(std::max(a.y, b.y) - 0.5)));
    for (int r = r0; r <= r1; ++r) {
      const double y = r + 0.5, t = b.y == a.y ? 0.0 : (y - a.y) / (b.y - a.y);
      const double x = a.x + t * (b.x - a.x);
      double& f = front_x[r];
      if (std::isnan(f) || (faces_left ? x < f : x > f)) f = x;
    }
  }
  cv::Mat mask(side.height, side.width, CV_8U, cv::Scalar(255));
  for (int r = 0; r < side.height; ++r) {
    if (std::isnan(front_x[r])) continue;
    const int edge = std::clamp(int(std::lround(front_x[r])), 0, side.width);  // first column
    // behind (faces_left) or one past the last column in front of the profile
    if (faces_left)
      mask.row(r).colRange(0, edge).setTo(0);
    else
      mask.row(r).colRange(edge, side.width).setTo(0);
  }
  return mask;
}

cv::Mat side_photo_mask(const FaceObservation& observation, cv::Size side_size) {
  const ViewObservation& s = observation.side;
  if (s.boundary.size() < 2 || s.width != side_size.width || s.height != side_size.height ||
      s.width <= 0 || s.height <= 0)
    return {};
  return profile_mask(s, observation.side_faces_left);
}

}  // namespace orthoface::vision
