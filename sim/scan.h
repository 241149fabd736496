#pragma once

#include <map>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"
#include "sim/head.h"

namespace orthoface::sim {

struct ScanOptions {
  std::string texture_path;            // texture image; overrides the file's own material
  bool gltf_uv_bottom_origin = false;  // see mesh::MeshReadOptions
  double mm_per_unit = 0;              // > 0: the scan's scale; 0: estimated (head_width_mm)
  double head_width_mm = 152;          // assumed skull breadth when the scale is estimated
  void check() const;                  // throws std::invalid_argument
};

// Loads a scanned head (any format mesh::read_mesh reads) into the head frame. The scan must
// be stored +y up with the face toward +z (as ../shared/data/lee_perry_smith_head). It is scaled
// to mm (mm_per_unit, or so that the widest skull section 35..85 mm below the top measures
// head_width_mm) and moved so the origin is between the ears (estimated: 125 mm below the top,
// in the middle of that section). Landmarks: scan_profile_landmarks. Throws std::runtime_error
// for file problems and std::invalid_argument for bad options.
Head load_scan(const std::string& path, const ScanOptions& options = {});

// Midline profile landmarks of a head-frame mesh found on its surface: nose_tip (most forward
// point within 10 mm of x = 0), nose_bridge, subnasale, lip_upper, lip_lower, chin, chin_bottom
// and forehead_top (midline, 65 mm above the bridge). Heuristic; a few mm on unusual faces.
// Throws std::runtime_error when the mesh has no recognisable profile.
std::map<std::string, Eigen::Vector3d> scan_profile_landmarks(const mesh::TriMesh& mesh);

// The mesh point whose texture coordinate is `uv` (TriMesh convention, v = 0 at the bottom);
// std::nullopt if no triangle covers it. Throws std::invalid_argument if the mesh has no uvs.
std::optional<Eigen::Vector3d> point_at_uv(const mesh::TriMesh& mesh, const Eigen::Vector2d& uv);

// The Lee Perry-Smith scan from data_dir (its folder: LeePerrySmith.glb or .obj, Map-COL.jpg)
// with every landmark of vision::kLandmarkNames: profile ones from scan_profile_landmarks, the
// others picked on Map-COL.jpg (documented in scan.cpp); the origin is then moved to the
// middle of the picked tragi (y, z). landmarks_picked is true.
// Throws std::runtime_error when the files are missing.
Head lee_perry_smith_head(const std::string& data_dir);

}  // namespace orthoface::sim
