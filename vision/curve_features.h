#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace orthoface::vision {

// Alternating extrema of a sequence: indices where v has a local maximum or minimum that stands
// out by at least `prominence` from the neighbouring opposite extrema (hysteresis scan).
struct Extremum {
  int index = 0;
  bool is_max = false;
};
std::vector<Extremum> alternating_extrema(const std::vector<double>& v, double prominence);

// Index in [a, b] of the point of `curve` farthest behind the chord from curve[a] to curve[b]
// on the side of +x (a concavity of a left-facing profile); returns a when b - a < 2.
// `depth` (optional) receives that distance in pixels.
int deepest_behind_chord(const std::vector<cv::Point2d>& curve, int a, int b, double* depth);

// Index in [a, b] whose tangent direction is closest to angle `angle_rad` (atan2(dy, dx)).
int tangent_closest(const std::vector<cv::Point2d>& curve, int a, int b, double angle_rad);

}  // namespace orthoface::vision
