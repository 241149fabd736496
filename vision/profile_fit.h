#pragma once

#include "vision/bspline.h"
#include "vision/edges.h"

namespace orthoface::vision {

struct ProfileFitOptions {
  int num_control = 16;        // control points of the B-spline profile model
  int samples = 160;           // points compared with the edge image per iteration
  int iterations = 6;          // model -> edges -> model loops (seed 004 §4)
  double search_px = 8.0;      // first half-width of the search along the normal
  double min_search_px = 2.0;  // the search shrinks to this
  double smoothness = 0.5;     // second-difference penalty on the control points
  int polarity = 0;            // +1: accept edges whose gradient points along the left-hand
                               // normal (-ty, tx), -1: against it, 0: either
  void check() const;          // throws std::invalid_argument on out-of-range values
};

struct ProfileFit {
  BSpline2d spline;
  double support = 0.0;         // fraction of samples that found an edge in the last pass
  double mean_residual_px = 0;  // mean |curve - edge| over supported samples, last pass
};

// Seed 004 §4: the profile model's control points are moved toward the edges found along the
// curve normals, the spline is regenerated, and this repeats with a shrinking search range.
// Throws std::invalid_argument when `initial` has < 4 control points or options are bad.
ProfileFit fit_profile_to_edges(const BSpline2d& initial, const EdgeImage& edges,
                                const ProfileFitOptions& options = {});

}  // namespace orthoface::vision
