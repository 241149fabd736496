#pragma once

#include <string>

#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::sim {

// Writes the simulation folder that `orthoface simulate` produces, into the existing folder `dir`:
//   front.png side.png            the photos (8-bit BGR)
//   front_mask.png side_mask.png  255 where the head covers the pixel
//   background.png background_side.png   the empty scene seen by the front / side camera
//   truth.obj truth.mtl truth.png the true mesh (mesh::write_mesh; head frame, mm)
//   landmarks.json                the truth (schema in sim/truth_json.h)
//   rig.yaml                      the NOMINAL rig (capture::write_rig; `reconstruct --rig`)
// Every file goes to a temporary beside it first; only when all are written are they renamed, so a
// failure leaves no partial set (the tmp files are removed). Throws std::runtime_error naming the
// file.
void write_simulation(const std::string& dir, const Head& head, const Capture& capture,
                      const RigOptions& options);

}  // namespace orthoface::sim
