// A new view composited into the front photo's frame: the subject's head and neck removed from
// the photo (a clean plate where the user has one, else inpainted), the rotated head drawn over.
#pragma once

#include <limits>

#include <opencv2/core.hpp>

#include "render/renderer.h"

namespace orthoface::render {

// `photo` (8-bit BGR) with `region` (CV_8U of its size, non-zero = what to remove, e.g. the head's
// view from the photo's own camera, grown past its edge) filled: from `clean_plate` (the empty
// scene, 8-bit BGR of the same size) when given, else by OpenCV's inpainting (Telea 2004) on a
// half-size copy, from the background alone when `subject` (CV_8U, non-zero = the whole subject,
// body included) is given, so skin and clothes do not bleed into the fill. Throws
// std::invalid_argument naming the input when a type or size differs.
cv::Mat head_removed(const cv::Mat& photo, const cv::Mat& region, const cv::Mat& clean_plate = {},
                     const cv::Mat& subject = {});

struct CompositeOptions {
  double feather_px = 1.0;  // the view's mask edge is softened over about this many pixels
  // The neck meets the photo's own: the view fades out from fade_from_row (fully drawn above)
  // to fade_to_row (not drawn below), so the body stays the photo's. Rows of the view; both
  // +infinity (the default): no fade.
  double fade_from_row = std::numeric_limits<double>::infinity();
  double fade_to_row = std::numeric_limits<double>::infinity();
};

// `view` (its image over its mask) drawn over `background` (8-bit BGR of the view's size).
// Throws std::invalid_argument when the sizes or types differ, feather_px is negative or
// fade_to_row is above fade_from_row.
cv::Mat composite(const RenderResult& view, const cv::Mat& background,
                  const CompositeOptions& options = {});

// `image` scaled by min(width / cols, height / rows) and centred in a black width x height frame
// (the framing of a view camera rescaled to that size). Throws std::invalid_argument on an empty
// image or a size of 0.
cv::Mat fitted(const cv::Mat& image, int width, int height);

}  // namespace orthoface::render
