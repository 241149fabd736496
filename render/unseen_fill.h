#pragma once

#include <opencv2/core.hpp>

namespace orthoface::render {

// Where no photo sees the surface of a new view (the side of the head turned toward the view
// that the front camera saw edge-on and the side camera never saw), the blend holds a flat
// fill colour. That share is replaced by the colour of the seen surface around the pixel:
// pull-push interpolation (Gortler et al. 1996, "The Lumigraph", §3.4), the seen pixels'
// colours averaged down an image pyramid and pushed back up into the holes, so a strip beside
// the hair takes the hair's colour and one beside the cheek the skin's.
//   image   CV_8UC3, the blend as rendered; changed in place where `unseen` > 0 inside `mask`
//   unseen  CV_8U, the share of `fill` in each pixel x255 (the synthesizer's weights, channel 2)
//   mask    CV_8U, the surface (non-zero) in the view; only its pixels give or take colour
//   fill    the colour the blend used where no photo sees the surface
// Pixels whose unseen share is below a tenth count as seen. Nothing changes when no pixel is
// unseen or none is seen. Returns the number of pixels changed. Throws std::invalid_argument
// naming the input when a type or size differs.
int fill_unseen(cv::Mat& image, const cv::Mat& unseen, const cv::Mat& mask, cv::Vec3b fill);

}  // namespace orthoface::render
