#pragma once

#include <opencv2/core.hpp>

namespace orthoface::render {

// Floating textures (Eisemann et al. 2008, "Floating Textures", Eurographics; §4 eq. 3-4) for
// the two photos of a new view. Where the mesh is not exactly the subject, each photo projected
// onto it puts an eye or a nostril at a different place in the new view, and a blend of the two
// shows the feature twice. Optical flow between the two projected images (OpenCV's DIS flow,
// Kroeger et al. 2016) finds how far apart each feature landed; each image is then warped to
// the position between them given by `alpha` (0: where the front photo put it, 1: where the side
// photo put it) before the usual blend, so a feature appears once, whichever photo colours it.
// The blend runs band by band (Burt & Adelson 1983): the two photos' difference in brightness
// fades over tens of pixels instead of showing as a seam.
struct FloatInputs {
  cv::Mat source[2];     // CV_8UC3: the new view coloured by the front (0) / side (1) photo alone
  cv::Mat available[2];  // CV_8U: 255 where that photo sees the surface (else its colour is junk)
  cv::Mat weights;       // CV_8UC3: the blend's shares x255 (front, side, unseen), as rendered
  cv::Mat mask;          // CV_8U: the surface (non-zero) in the new view
  cv::Vec3b fill{128, 128, 128};  // BGR where no photo sees the surface
  double alpha = 0;               // 0..1: the geometry's reference (see above)
  int bands = 6;  // the aligned images are blended in this many Laplacian bands (1: per pixel)
  // Keep only flow that survives a round trip (forward then backward within a few pixels); where
  // the photos show different things the rest has no correspondence behind it and would smear a
  // feature. false warps by the raw flow, which makes two photos of different people visibly
  // disagree (what reconstruct's identity check wants to see).
  bool round_trip = true;
};

struct FloatResult {
  cv::Mat image;             // CV_8UC3: the blend of the two warped images (background untouched
                             // where mask is 0: the caller's background is kept from `base`)
  double mean_shift_px = 0;  // mean flow length over the pixels both photos see (0 if none)
  int overlap_pixels = 0;    // pixels both photos see
};

// Blends the warped sources over `base` (the view as rendered, CV_8UC3, whose background stays).
// Throws std::invalid_argument naming the input when a size or type differs or alpha is not in
// 0..1.
FloatResult float_textures(const FloatInputs& in, const cv::Mat& base);

// The geometry reference of a new view between the front and side cameras (unit directions from
// the head toward each camera and toward the new view): the angle to the front camera over the
// sum of the angles to both (0 at the front camera, 1 at the side camera, 0.5 half-way).
double float_alpha(const cv::Vec3d& to_view, const cv::Vec3d& to_front, const cv::Vec3d& to_side);

}  // namespace orthoface::render
