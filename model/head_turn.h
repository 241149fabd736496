#pragma once

// How far the head was turned in the front photo, and the stereo data turned back to face it.
// People never sit at exactly 0 and 90 degrees: a head turned by t in the front photo is seen at
// 90 - t (or 90 + t) by the side camera, and seed 004's reconstruction, which takes the front
// photo as frontal, deforms a frontal base mesh onto a turned face (an asymmetric, sheared
// head whose mirror image is not the other side). The turn is estimated from the trained
// landmarker's front points (the nose tip leaves the eyes' midline by its depth x sin t),
// the stereo data is turned back, the base mesh adapted facing front, and the result turned
// back to where the head stood, so the photos still texture it from where they were taken.

#include <optional>
#include <string>

#include <Eigen/Core>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"
#include "model/stereo.h"
#include "vision/observation.h"

namespace orthoface::model {

// A rotation of the head about a vertical axis of the head frame: a head-facing point p_h is
// seen at axis + R_y(yaw) (p_h - axis), R_y(yaw) taking +z (the face) toward +x (the subject's
// left, the front image's right) for yaw > 0.
struct HeadTurn {
  double yaw_rad = 0;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // a point on the axis (y unused), mm
  double scale = 1;                                // the face over the generic head's
  int points = 0;                                  // landmarks the fit kept
  double residual_mm = 0;                          // their RMS lateral residual
};

// The head's yaw in the front photo: a weak-perspective fit of the trained landmarker's front
// points (observation.front_trained) to the generic head's landmarks, x = axis_x + s (x_g cos t
// + z_g sin t), least squares, points beyond 3 median residuals dropped once; the axis depth
// from the features the side photo gave depth. nullopt with fewer than 6 usable points, no
// feature with depth, or a fit that is not a face (scale outside 0.5..2). Throws
// std::invalid_argument on a non-finite point.
std::optional<HeadTurn> estimate_head_turn(const vision::FaceObservation& observation,
                                           const capture::RigCalibration& rig,
                                           const StereoData& data);

// `data` as the head would have been seen facing the front camera (turn.yaw_rad undone):
// features rotated about the axis (those without depth at the generic head's depth), the centre
// line moved onto the axis, the silhouette as it is (a turned head's depth makes up for its
// foreshortened width) and the profile deepened by 1 / cos t (the most projecting points lie on
// the midline).
StereoData facing_front(const StereoData& data, const HeadTurn& turn);

// Turns a head-facing point or mesh to where the head stood (turn applied).
Eigen::Vector3d turned(const Eigen::Vector3d& p, const HeadTurn& turn);
void turn_mesh(mesh::TriMesh& mesh, const HeadTurn& turn);

}  // namespace orthoface::model
