#pragma once

#include <array>
#include <string>
#include <string_view>

namespace orthoface::vision {

// Canonical landmark names shared by sim (ground truth), vision (detection) and model (base-mesh
// feature vertices). "left" / "right" are the SUBJECT's: the subject's left is head +x, which is
// the image right in the front view and the side nearer the side camera.
// Midline landmarks (no side suffix) are seen in both views; the side view shows the profile.
inline constexpr std::array<std::string_view, 30> kLandmarkNames = {
    "forehead_top",  // hairline / top of forehead, midline
    "brow_left_inner",
    "brow_left_center",
    "brow_left_outer",
    "brow_right_inner",
    "brow_right_center",
    "brow_right_outer",
    "nose_bridge",  // deepest point between the eyes (nasion)
    "eye_left_inner",
    "eye_left_center",
    "eye_left_outer",
    "eye_right_inner",
    "eye_right_center",
    "eye_right_outer",
    "nose_tip",  // pronasale
    "alar_left",
    "alar_right",  // outermost points of the nostril wings
    "subnasale",
    "mouth_left",
    "mouth_right",  // mouth corners
    "lip_upper",
    "lip_lower",    // lip midpoints (most projecting)
    "chin",         // pogonion, most projecting chin point
    "chin_bottom",  // gnathion / menton, lowest chin point
    "ear_left_top",
    "ear_right_top",
    "ear_left_tragus",
    "ear_right_tragus",
    "cheek_left",
    "cheek_right",  // widest face points at nose-tip height
};

// Midline landmarks: the ones whose 3D position the side profile gives directly.
inline constexpr std::array<std::string_view, 7> kProfileLandmarkNames = {
    "forehead_top", "nose_bridge", "nose_tip", "subnasale", "lip_upper", "lip_lower", "chin"};

// True when `name` is one of kLandmarkNames.
bool is_landmark_name(std::string_view name);

// The name of the same landmark on the other side of the face ("eye_left_outer" ->
// "eye_right_outer"); midline names map to themselves. Throws std::invalid_argument for a name
// that is not in kLandmarkNames.
std::string mirrored_name(std::string_view name);

}  // namespace orthoface::vision
