#pragma once

#include <map>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "mesh/tri_mesh.h"

namespace orthoface::sim {

// A head with known ground truth: textured, closed, manifold mesh in the head frame (mm,
// DESIGN.md) and 3D landmarks named as in vision/landmarks.h.
struct Head {
  mesh::TriMesh mesh;
  std::map<std::string, Eigen::Vector3d> landmarks;
  std::string name;               // "sim seed N", "Lee Perry-Smith scan", ...
  bool landmarks_picked = false;  // true: picked on a scan by hand / heuristics (a few mm off)
};

// Shape and appearance of a simulated head. Lengths in mm (head frame: origin between the
// tragi, +x subject's left, +y up, +z out of the face), the rest are ratios. Defaults = seed 0,
// an average adult head. Realistic ranges in the comments; check() allows wider ones.
struct HeadParams {
  double head_width = 152;                     // max skull breadth (140..165)
  double head_depth = 195;                     // glabella to back of the head (180..210)
  double head_height = 235;                    // vertex (top) to menton (chin bottom) (220..250)
  double nose_length = 50;                     // nasion to subnasale, vertical (44..58)
  double nose_projection = 20;                 // tip in front of the subnasale (15..26)
  double nose_width = 35;                      // alar width (30..42)
  double mouth_width = 50;                     // corner to corner (44..58)
  double lip_fullness = 1.0;                   // lip thickness ratio (0.6..1.5)
  double chin_projection = 0;                  // chin forward (+) / back (-) of average (-6..+6)
  double chin_height = 45;                     // stomion to menton (38..52)
  double jaw_width = 105;                      // bigonial breadth (92..120)
  double eye_spacing = 63;                     // between the eye centres (57..70)
  double eye_width = 29;                       // eye corner to corner (26..32)
  double brow_ridge = 4;                       // brow ridge protrusion (1..8)
  double ear_height = 0;                       // ear shift up (+) / down (-) (-8..+8)
  double ear_size = 62;                        // ear length (54..70)
  double ear_protrusion = 14;                  // how far the ears stand out (8..20)
  double cheek_fullness = 0.5;                 // 0 gaunt .. 1 full
  double neck_width = 105;                     // (92..120)
  double neck_length = 75;                     // menton to the bottom of the neck (60..90)
  double skin_tone = 0.3;                      // 0 very light .. 1 very dark
  double skin_redness = 0.5;                   // 0 olive .. 1 pink
  double hair_darkness = 0.8;                  // 0 blond .. 1 black
  Eigen::Vector3d iris_rgb{0.35, 0.22, 0.12};  // RGB in [0, 1]
  double asymmetry = 0;  // 0 = mirror symmetric; 1 = nose and mouth 3 mm to +x, left eye 2 mm up

  // Throws std::invalid_argument naming the first non-finite or out-of-range field.
  void check() const;
};

struct HeadOptions {
  int target_triangles = 4000;  // ~4k default, kHighTriangles for detail; ignored if rings > 0
  int rings = 0;                // > 0: rings from crown to neck bottom (then segments too)
  int segments = 0;             // > 0: vertices around each ring (even)
  int texture_size = 1024;      // square texture, pixels
  static constexpr int kHighTriangles = 16000;

  // Throws std::invalid_argument on out-of-range values.
  void check() const;
};

// Deterministic parameters for `seed` (>= 0): seed 0 = the defaults, others vary every shape
// and appearance field within the realistic ranges above. Throws std::invalid_argument if seed < 0.
HeadParams head_params(int seed);

// Closed, manifold (after welding the UV seam), symmetric head with texture and all landmarks of
// vision::kLandmarkNames on its surface. Throws std::invalid_argument on bad params / options.
Head make_head(const HeadParams& params, const HeadOptions& options = {});
Head make_head(int seed);

// The head with its mouth open: the lower lip, jaw and chin turned down about the jaw's hinge
// (between the tragi) until the chin is `open_mm` lower; nothing above the lips' line moves, the
// neck's base stays, landmarks move with the surface. The texture's dark line between the lips
// stretches into the open mouth. open_mm = 0 gives the head as it is. Throws
// std::invalid_argument when open_mm is outside [0, kMaxMouthOpenMm] or the head lacks a
// lip_upper, lip_lower, mouth corner, chin, chin_bottom or tragus landmark.
inline constexpr double kMaxMouthOpenMm = 20;
Head open_mouth(const Head& head, double open_mm);

// The section of the head surface at height y_mm: what the front view's silhouette (x range) and
// the side view's profile (z range) show on that row. std::nullopt if y is outside the mesh.
struct SilhouetteExtremes {
  double min_x = 0, max_x = 0;  // front view extremes (mm)
  double min_z = 0, max_z = 0;  // side view extremes: back of head and profile (mm)
};
std::optional<SilhouetteExtremes> silhouette_extremes(const Head& head, double y_mm);
// The same for any mesh (in its own units). Throws std::invalid_argument if y is not finite.
std::optional<SilhouetteExtremes> silhouette_extremes(const mesh::TriMesh& mesh, double y);

}  // namespace orthoface::sim
