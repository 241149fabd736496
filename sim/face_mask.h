#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "render/renderer.h"
#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::sim {

// The face region used by new-view metrics (DESIGN.md: PSNR / SSIM inside the face mask):
// vertices between the chin (chin_bottom, 5 mm lower) and the hairline (forehead_top) and at
// least 15 mm in front of the ear tragi. Indexed like head.mesh.vertices. Throws
// std::invalid_argument when one of those four landmarks is missing.
std::vector<bool> face_vertices(const Head& head);

// CV_8U mask, 255 where the visible surface in `camera`'s view belongs to the face region
// (depth-tested against the whole head, so an occluded face part is not in the mask).
// Throws as face_vertices and render::Renderer::render.
cv::Mat face_mask(const Head& head, const capture::CameraModel& camera, render::Renderer& renderer);

// CV_8U mask of `size`, 255 inside the convex hull of the head's landmarks seen by `camera`
// (brows to chin, cheek to cheek: the ears and forehead_top left out), the face as the live
// benchmarks score it, occlusion not tested.
cv::Mat landmark_hull_mask(const Head& head, const capture::CameraModel& camera, cv::Size size);

// True when `head` has the landmarks face_vertices needs.
bool has_face_landmarks(const Head& head);

// The camera true_view (sim/rig.h) renders from: the nominal front camera's intrinsics turned to
// yaw / pitch (radians). Throws std::invalid_argument on bad options or non-finite angles.
capture::CameraModel true_view_camera(const RigOptions& options, double yaw_rad, double pitch_rad);

}  // namespace orthoface::sim
