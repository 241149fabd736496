#pragma once

#include <string>

#include "sim/head.h"
#include "sim/rig.h"

namespace orthoface::sim {

// Writes the simulation folder that `orthoface simulate` produces, into the existing folder `dir`:
//   front.png side.png            the photos (8-bit BGR)
//   front_mask.png side_mask.png  255 where the head covers the pixel
//   background.png background_side.png   the empty scene seen by the front / side camera
//   truth.obj truth.mtl truth_texture.png   the true mesh (head frame, mm; texture if any)
//   landmarks.json                the truth (schema in sim/truth_json.h)
//   rig.yaml                      the NOMINAL rig (capture::write_rig; `reconstruct --rig`)
// Every file goes to name.tmp first; only when all are written are they renamed, so a failure
// leaves no partial set (the tmp files are removed). Throws std::runtime_error naming the file.
void write_simulation(const std::string& dir, const Head& head, const Capture& capture,
                      const RigOptions& options);

// Writes `mesh` as Wavefront OBJ at obj_path ("dir/name.obj"), plus name.mtl and
// name_texture.png when it has uvs and a texture; vertex colours as "v x y z r g b". Each file
// goes via .tmp + rename. Throws std::runtime_error naming a file that cannot be written.
void write_obj(const model::TriMesh& mesh, const std::string& obj_path);

}  // namespace orthoface::sim
