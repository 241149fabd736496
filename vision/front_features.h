#pragma once

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/front_boundary.h"
#include "vision/observation.h"

namespace orthoface::vision {

// Front-view symmetry axis: x = centre_x + tan(roll) * (y - centre_y), index coordinates.
struct CentreLine {
  double centre_x = 0, centre_y = 0, roll_rad = 0, confidence = 0;
};

struct FrontFeatures {
  std::map<std::string, Feature2d> features;  // index coordinates
  CentreLine centre;
  std::vector<std::string> warnings;
};

// Eyes, brows, nose, mouth, chin and cheeks in the front view (seed 004 §4): a position model
// placed by the boundary and by `rows` (front-view rows of midline landmarks, e.g. from the side
// profile through the shared row of seed 004 eq. 1; may be empty) gives the first guess; local
// filters (dark blobs, colour components, edges) refine it; a side not found is mirrored across
// the centre line. `head_height_px` is the crown-to-chin height (<= 0: from the boundary).
// Throws std::invalid_argument when `bgr` is not 8-bit BGR.
FrontFeatures front_features(const cv::Mat& bgr, const FrontBoundary& boundary,
                             const std::map<std::string, double>& rows, double head_height_px);

// `p` reflected across the centre line.
cv::Point2d mirror_point(const CentreLine& line, cv::Point2d p);

}  // namespace orthoface::vision
