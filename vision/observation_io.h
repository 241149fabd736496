#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "vision/observation.h"

namespace orthoface::vision {

// FaceObservation <-> JSON: {"front": {width, height, boundary: [[x,y],...], boundary_confidence,
// features: {name: {x, y, confidence, method, mirrored}}}, "side": {...}, "centre_line":
// {x_px, y_px, roll_rad, confidence}, "side_faces_left", "warnings": [...]}. Pixels as in the
// observation (capture/camera_model.h convention).
nlohmann::json to_json(const FaceObservation& obs);

// Throws std::invalid_argument naming the first missing or mistyped field, or a feature name
// that is not in vision/landmarks.h.
FaceObservation observation_from_json(const nlohmann::json& j);

// observation.json writer (all or nothing, io/atomic_file.h) and reader. Throw std::runtime_error
// naming the file when it cannot be written / read / parsed.
void write_observation(const FaceObservation& obs, const std::string& path);
FaceObservation read_observation(const std::string& path);

}  // namespace orthoface::vision
