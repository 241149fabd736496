#pragma once

#include <opencv2/core.hpp>

#include "vision/front_features.h"

namespace orthoface::vision {

// Local filters for the front-view features (used by front_features; index coordinates).
struct FilterContext {
  cv::Mat bgr, grey, lab;   // lab: 8-bit OpenCV Lab; grey and lab are set inside roi only
  cv::Rect roi;             // face box around the skin point; filter windows are clipped to it
  cv::Vec3f skin{0, 0, 0};  // Lab of the cheek skin
};
// Grey and Lab images inside `box` (clipped to the image; the filters' windows) plus the skin
// colour around `skin_at` (a patch of size ~0.1 W, inside the box).
FilterContext make_filter_context(const cv::Mat& bgr, cv::Point2d skin_at, double W,
                                  const cv::Rect& box);

struct EyeFound {
  bool ok = false;
  cv::Point2d centre, corner_image_left, corner_image_right;
  double confidence = 0;
};
// Eye on the image-left (true) or image-right side: iris = darkest blob of the position-model
// window, corners = ends of the non-skin component around it.
EyeFound find_eye(const FilterContext& ctx, double x0, double r_nasion, double W, double H,
                  bool image_left);

// Eye of the visible side in a profile photo: the non-skin component (sclera, iris, lashes)
// just behind the profile at the front view's eye row (the shared row of seed 004 eq. 1, searched
// +-0.035 H), its centre at the iris (darkest point inside it), its outer corner at the component's
// back end. x_profile: the profile's column at that row; behind: +1 when the face looks toward
// the image left, -1 otherwise; H: head height in pixels. corner_image_left / right hold the
// component's front / back ends whichever way the face looks.
EyeFound find_side_eye(const FilterContext& ctx, double x_profile, double row, double H,
                       double behind);

struct MouthFound {
  bool ok = false;
  cv::Point2d corner_image_left, corner_image_right;
  double confidence = 0;
};
// Mouth corners: ends of the red / dark lip component between the lip rows.
MouthFound find_mouth(const FilterContext& ctx, double x0, double r_lu, double r_ll, double W,
                      double H);

struct NoseFound {
  bool ok = false;
  cv::Point2d alar_image_left, alar_image_right;
  double confidence = 0;
};
// Alar points: nostrils as dark blobs, wing edges outside them (position model if no edge).
NoseFound find_nose(const FilterContext& ctx, double x0, double r_tip, double r_sub, double W,
                    double H);

void add_eye_features(const EyeFound& image_left, const EyeFound& image_right, FrontFeatures& out);
void add_brow_features(const FilterContext& ctx, const EyeFound& image_left,
                       const EyeFound& image_right, double W, double H, FrontFeatures& out);
void add_nose_mouth_features(const NoseFound& nose, const MouthFound& mouth, FrontFeatures& out);
// Copies each left/right feature found on one side only across the centre line (seed 004 §4).
void mirror_missing(FrontFeatures& out);

}  // namespace orthoface::vision
