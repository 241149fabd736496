#pragma once

#include <memory>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"

namespace orthoface::render {

// Lighting for shaded renders: colour = albedo * (ambient + diffuse * max(0, n . -direction)).
// ambient = 1, diffuse = 0 (the default) shows the texture / vertex colours unlit.
struct Light {
  Eigen::Vector3d direction_head{0.0, 0.0, -1.0};  // direction the light travels, head frame
  double ambient = 1.0;
  double diffuse = 0.0;
};

struct RenderOptions {
  cv::Scalar background{0, 0, 0};  // BGR 0..255
  Light light;
  bool cull_back_faces = true;             // faces whose outward normal points away from the camera
  bool wireframe = false;                  // draw triangle edges over the surface (figures)
  cv::Scalar wireframe_color{40, 40, 40};  // BGR 0..255
  bool read_depth = true;  // false: image and mask only, depth_mm left empty (a faster frame)
};

// Largest image width or height a render accepts, pixels.
inline constexpr int kMaxRenderSize = 8192;

// One rendered view. Pixel (c, r) covers image area [c, c+1) x [r, r+1), origin top-left.
struct RenderResult {
  cv::Mat image;     // CV_8UC3 BGR
  cv::Mat depth_mm;  // CV_32F, z_cam of the visible surface in mm; +infinity where empty
                     // (empty when RenderOptions::read_depth is false)
  cv::Mat mask;      // CV_8U, 255 where the mesh covers the pixel centre, else 0
};

// Owns one OSMesa context (software GL, no display, no GPU). Meshes are drawn with their
// texture when mesh.texture and mesh.uvs are set, else with mesh.colors, else light grey.
// The camera's own intrinsics and pose decide the projection, so a render from the rig's
// CameraModel lands exactly where capture::project puts each point (distortion is ignored).
// Throws std::runtime_error if the context cannot be created (naming libOSMesa) and
// std::invalid_argument on an empty mesh, bad indices or an image size out of range.
// Use one Renderer from one thread at a time. llvmpipe rasterises on LP_NUM_THREADS threads
// (default: the number of cores; 0 = in the calling thread).
class Renderer {
 public:
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // The mesh is uploaded once and kept (up to 8 meshes, least recently used dropped) keyed by
  // its buffers' addresses, sizes and a hash of the geometry; a texture edited in place under
  // the same buffer may go unnoticed: call clear_cache() after such an edit.
  RenderResult render(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                      const RenderOptions& options = {});
  void clear_cache();
  int cached_meshes() const;  // meshes currently uploaded

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-off render with a temporary context.
RenderResult render_once(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                         const RenderOptions& options = {});

}  // namespace orthoface::render
