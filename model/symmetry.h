#pragma once

#include <map>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace orthoface::model {

// The subject's mid-sagittal plane from named 3D landmarks (head frame, mm; vision/landmarks.h
// names): the normal is the mean direction from each right feature to its left twin, the offset
// the mean over the twins' midpoints and the midline features (nose tip, chin, ...). Returned as
// (n, d) with |n| = 1 and n . p = d on the plane, n pointing to the subject's left. nullopt with
// fewer than two left / right pairs. Throws std::invalid_argument on a non-finite landmark.
std::optional<Eigen::Vector4d> mid_sagittal_plane(
    const std::map<std::string, Eigen::Vector3d>& landmarks);

// The reflection through `plane` (as above) as a 4x4 affine matrix of the head frame.
Eigen::Matrix4d reflection(const Eigen::Vector4d& plane);

}  // namespace orthoface::model
