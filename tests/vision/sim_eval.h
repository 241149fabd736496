#pragma once
// Scoring of a vision observation against the sim rig's ground truth (used by vision_test and
// bench/vision_bench). Pixels follow capture/camera_model.h.

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sim/rig.h"
#include "vision/observation.h"

namespace orthoface::testing {

// Points on the true silhouette: midpoints of the pixel edges between inside and outside pixels.
inline std::vector<cv::Point2d> mask_edge_points(const cv::Mat& mask) {
  std::vector<cv::Point2d> pts;
  for (int r = 0; r < mask.rows; ++r)
    for (int c = 0; c < mask.cols; ++c) {
      const bool a = mask.at<uchar>(r, c) != 0;
      if (c + 1 < mask.cols && a != (mask.at<uchar>(r, c + 1) != 0))
        pts.emplace_back(c + 1.0, r + 0.5);
      if (r + 1 < mask.rows && a != (mask.at<uchar>(r + 1, c) != 0))
        pts.emplace_back(c + 0.5, r + 1.0);
    }
  return pts;
}

// Mean distance (px) from each curve point to the true silhouette of `mask`; -1 if empty.
inline double curve_to_mask_error(const std::vector<cv::Point2d>& curve, const cv::Mat& mask) {
  const auto edge = mask_edge_points(mask);
  if (curve.empty() || edge.empty()) return -1;
  double sum = 0;
  for (const auto& p : curve) {
    double best = 1e18;
    for (const auto& q : edge)
      best = std::min(best, (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y));
    sum += std::sqrt(best);
  }
  return sum / curve.size();
}

struct SimScore {
  std::map<std::string, double> front_err, side_err;  // per landmark, px (visible ones found)
  double boundary_err = -1, profile_err = -1;
  std::vector<std::string> missing;  // visible in truth, not in the observation
};

inline double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Landmarks skipped in scoring: ears come from a position model only.
inline bool scored(const std::string& name) { return name.find("ear_") != 0; }

inline SimScore score(const vision::FaceObservation& obs, const sim::Capture& cap) {
  SimScore s;
  for (const auto& [name, t] : cap.landmarks) {
    if (!scored(name)) continue;
    if (t.visible_front) {
      const auto it = obs.front.features.find(name);
      if (it == obs.front.features.end())
        s.missing.push_back("front:" + name);
      else
        s.front_err[name] =
            std::hypot(it->second.px.x - t.front_px.x(), it->second.px.y - t.front_px.y());
    }
    if (t.visible_side) {
      const auto it = obs.side.features.find(name);
      if (it != obs.side.features.end())
        s.side_err[name] =
            std::hypot(it->second.px.x - t.side_px.x(), it->second.px.y - t.side_px.y());
    }
  }
  s.boundary_err = curve_to_mask_error(obs.front.boundary, cap.front_mask);
  s.profile_err = curve_to_mask_error(obs.side.boundary, cap.side_mask);
  return s;
}

inline std::vector<double> all_errors(const SimScore& s) {
  std::vector<double> v;
  for (const auto& [n, e] : s.front_err) v.push_back(e);
  for (const auto& [n, e] : s.side_err) v.push_back(e);
  return v;
}

}  // namespace orthoface::testing
