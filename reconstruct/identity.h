#pragma once
// Is the side photo's face the front photo's person? The face-recognition network
// (vision/face_descriptor.h) cannot match a front photo with a profile, but it can match it with
// the model's own 45-degree view toward the photographed side, whose face carries the side
// photo's near half on the shape fitted to both (docs/input_check.md, "Telling two people apart").

#include <optional>

#include "reconstruct/reconstruction.h"

namespace orthoface::reconstruct {

// The descriptor distance between the front photo's face and the face of the reconstruction's
// view at 45 degrees toward the photographed side (drawn as `orthoface render` draws it, over
// the front photo's scene). Each face is placed where the model's landmarks project (eye, brow
// and mouth corners, nose tip, chin) and refined by the landmark network. nullopt when the
// networks' weights cannot be read or the reconstruction has no photos or landmarks.
std::optional<double> front_to_view_face_distance(const Reconstruction& reconstruction);

}  // namespace orthoface::reconstruct
