#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::render {

struct InheritOptions {
  bool equalize = true;     // colour-equalise the photos first (as ViewSynthesizer)
  int padding_px = 4;       // photo pixels kept around each used region of the atlas
  int max_atlas_px = 8192;  // the atlas is scaled down to fit this side
  void check() const;       // throws std::invalid_argument naming the bad field
};

struct InheritedMesh {
  mesh::TriMesh mesh;       // uvs into texture = the atlas
  std::vector<int> source;  // per triangle of the input: 0 front, 1 side, -1 fill colour
};

// The mesh with the texture it inherits from the two photos (seed 004 §6, per triangle): each
// triangle takes the photo that sees all its vertices (depth-map test) and that it faces more;
// a triangle no photo sees maps to a patch of the fill colour. The atlas holds the used regions
// of both photos side by side; where triangles of both photos meet, a vertex keeps its index
// for the first and copies are appended for the other (welding them gives the input back).
// Throws std::invalid_argument on a bad mesh, rig or photo (as ViewSynthesizer).
InheritedMesh inherit_texture(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                              const cv::Mat& front, const cv::Mat& side,
                              const InheritOptions& options = {});

// The mesh with per-vertex colours (RGB 0..1) inherited the same way per vertex (uvs and
// texture dropped), for PLY export and colour-only viewers.
mesh::TriMesh inherit_vertex_colours(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                                     const cv::Mat& front, const cv::Mat& side,
                                     const InheritOptions& options = {});

// Binary glTF 2.0 with the texture embedded as PNG: POSITION (metres, = mm / 1000, glTF's unit;
// head frame axes match glTF's +y up, +z front), NORMAL, TEXCOORD_0 (v flipped to glTF's top
// origin), uint32 indices, one unlit-looking PBR material. Written all or nothing
// (io/atomic_file.h). Throws std::invalid_argument if the mesh has no uvs / texture,
// std::runtime_error on IO errors.
void write_glb(const mesh::TriMesh& textured, const std::string& path);

}  // namespace orthoface::render
