#pragma once
// The iBUG 300-W 68-point layout (used by 300-W, dlib, OpenFace and our trained front network,
// vision/face_landmarks68.h) and how its points relate to our named landmarks
// (vision/landmarks.h). Indices are 0-based: jaw 0-16, brows 17-26, nose bridge 27-30, lower
// nose 31-35, eyes 36-47, mouth 48-67. iBUG numbers the points as the image shows them, so the
// image-left ones are the SUBJECT's right: e.g. 36 (image-left outer eye corner) is
// eye_right_outer and 45 (image-right outer eye corner) is eye_left_outer.

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <opencv2/core.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

inline constexpr int kIbug68Count = 68;

// 68 points in the iBUG layout; std::nullopt = a point that is not known.
using Ibug68 = std::array<std::optional<cv::Point2d>, kIbug68Count>;

// Our landmarks that are one iBUG point each (name, index). eye_*_center and chin are not
// iBUG points: named_from_ibug68 derives them from several.
inline constexpr std::array<std::pair<std::string_view, int>, 20> kIbug68Landmarks = {{
    {"eye_right_outer", 36},  {"eye_right_inner", 39},  {"eye_left_inner", 42},
    {"eye_left_outer", 45},   {"brow_right_outer", 17}, {"brow_right_center", 19},
    {"brow_right_inner", 21}, {"brow_left_inner", 22},  {"brow_left_center", 24},
    {"brow_left_outer", 26},  {"mouth_right", 48},      {"mouth_left", 54},
    {"alar_right", 31},       {"alar_left", 35},        {"nose_bridge", 27},
    {"nose_tip", 30},         {"subnasale", 33},        {"lip_upper", 51},
    {"lip_lower", 57},        {"chin_bottom", 8},
}};

// The iBUG index of landmark `name` (kIbug68Landmarks), or -1 for a landmark with no iBUG point
// (e.g. forehead_top, eye_left_center). Throws std::invalid_argument for a name that is not in
// kLandmarkNames.
int ibug68_index(std::string_view name);

// Our named landmarks from iBUG points, in the points' own pixel convention: every
// kIbug68Landmarks entry whose point is known, plus eye_{left,right}_center (mean of the eye's
// six points 36-41 / 42-47, when all are known) and chin (the most forward chin point: 0.8 of
// the way from the lower lip 57 to the chin's bottom 8; sim heads give 0.84). Throws
// std::invalid_argument when a known point is not finite.
std::map<std::string, cv::Point2d> named_from_ibug68(const Ibug68& points);

// The inverse for the landmarks that are iBUG points: each kIbug68Landmarks name found in
// `features` at its index, every other index unknown. Names without an iBUG point are ignored.
// Throws std::invalid_argument when such a feature's position is not finite.
Ibug68 ibug68_from_named(const std::map<std::string, Feature2d>& features);

}  // namespace orthoface::vision
