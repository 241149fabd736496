#pragma once

#include <map>
#include <string>

#include "capture/camera_model.h"
#include "sim/rig.h"

namespace orthoface::sim {

// The ground truth that `orthoface simulate` writes as landmarks.json. Schema (version 1):
// {
//   "format": "orthoface-truth", "version": 1,
//   "subject": "sim seed 3",            // Head::name
//   "seed": 3,                          // RigOptions::seed (noise, clutter)
//   "mesh": "truth.obj",                // file name of the true mesh, next to this file
//   "image_size": [640, 480],           // width, height, pixels
//   "units": "mm (head frame, DESIGN.md); px (origin top-left, pixel centre = index + 0.5)",
//   "options": {"rig": "ideal"|"perspective", "px_per_mm", "focal_px", "distance_mm",
//               "front_error"/"side_error": {"roll_deg","yaw_deg","pitch_deg","offset_mm":[x,y,z]},
//               "ambient", "diffuse", "light_direction": [x,y,z], "noise_sigma", "blur_sigma",
//               "background": "plain"|"cluttered"|"photo", "background_photo": PATH ("" unless
//               photo), "background_bgr": [b,g,r]},
//   "cameras": {"true": RIG, "nominal": RIG},   // RIG = {"front": CAM, "side": CAM}
//      CAM = as in rig.yaml: {"projection": "orthographic"|"perspective", "width", "height",
//             "camera_matrix": [[fx,0,cx],[0,fy,cy],[0,0,1]], "distortion": [k1,k2,p1,p2,k3],
//             "cam_from_head": 4x4 row-major nested array}
//   "landmarks": {NAME: {"xyz_mm": [x,y,z], "front_px": [u,v], "side_px": [u,v],
//                        "visible_front": bool, "visible_side": bool}}
// }
struct Truth {
  std::string subject;
  std::string mesh_file;
  RigOptions options;  // includes seed and image size
  capture::RigCalibration true_rig, nominal_rig;
  std::map<std::string, LandmarkTruth> landmarks;
};

// Truth of a capture: rigs and landmarks from `capture`, the rest from the arguments.
Truth make_truth(const Capture& capture, const RigOptions& options, const std::string& subject,
                 const std::string& mesh_file);

// Writes the schema above to a temporary beside it, then renames. Throws std::runtime_error when
// the file cannot be written.
void write_truth_json(const Truth& truth, const std::string& path);

// Reads a file written by write_truth_json. Throws std::runtime_error naming the file and the
// missing or malformed field (and for a file that is not JSON).
Truth read_truth_json(const std::string& path);

}  // namespace orthoface::sim
