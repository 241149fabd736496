#pragma once
// Is the side photo's face the front photo's person? The face-recognition network
// (vision/face_descriptor.h) cannot match a front photo with a profile, but it can match it with
// the model's own views at 45-65 degrees toward the photographed side, whose faces carry the
// side photo's near half on the shape fitted to both (docs/input_check.md, "Telling two people
// apart").

#include <optional>

#include "reconstruct/reconstruction.h"

namespace orthoface::reconstruct {

// The views the check looks at: degrees toward the photographed side. One view's distance
// swings with the angle (the 26 FRMDB pairs' separation, ROC area, 0.83 at 45 degrees, 0.86 at
// 55, 0.90 at 65, 0.78 at 70); the mean over three is steadier (0.905).
inline constexpr double kIdentityViewsDeg[] = {45, 55, 65};

// The mean descriptor distance between the front photo's face and the faces of the
// reconstruction's views at kIdentityViewsDeg toward the photographed side (drawn as `orthoface
// render` draws them, over the front photo's scene, but blended per pixel and aligned by the
// raw flow). Each face is placed where the model's landmarks project (eye, brow and mouth
// corners, nose tip, chin) and refined by the landmark network; a view whose face falls outside
// the image is left out. nullopt when the networks' weights cannot be read, the reconstruction
// has no photos or landmarks, or no face could be placed.
std::optional<double> front_to_view_face_distance(const Reconstruction& reconstruction);

}  // namespace orthoface::reconstruct
