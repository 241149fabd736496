#pragma once

#include "sim/rig.h"
#include "vision/observation.h"

namespace orthoface::sim {

// The observation a perfect vision stage would make of `capture`: the front silhouette and the
// side profile from the true masks (outermost head pixel per row: both sides in the front view,
// the image-left one in the side view), the centre line fitted through the true midline
// landmarks, and every landmark visible in a view at its true pixel (confidence 1, method
// "truth"). Used to separate vision error from model error. Throws std::invalid_argument when
// a mask is empty or not CV_8U.
vision::FaceObservation truth_observation(const Capture& capture);

}  // namespace orthoface::sim
