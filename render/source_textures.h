#pragma once

// Internal to render/: the source photos and depth maps of ViewSynthesizer (render/new_view.cpp)
// as GL textures.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "capture/camera_model.h"
#include "render/gl_util.h"

namespace orthoface::render::detail {

// One source camera's textures and CPU copies.
struct SourceGl {
  GLuint zmap = 0, photo = 0, photo_eq = 0;  // zmap: linear depth texture, compare mode
  GLuint lut = 0, eq_fbo = 0;                // equalisation: 3D colour lookup, FBO on photo_eq
  GLuint depth_fbo = 0;                      // framebuffer on zmap
  cv::Size zmap_size;                        // allocated size of zmap
  cv::Size photo_size, photo_eq_size;        // allocated sizes of photo, photo_eq
  std::array<double, 2> zrange{0, 0};        // near, far of zmap
  cv::Mat depth;                             // z_cam (mm), CV_32F, +inf where empty
  bool depth_stale = false;                  // zmap re-rendered since `depth` was read
  cv::Mat raw;                               // the photo as set (buffer reused)
  cv::Mat mask;                              // subject mask (alpha), eroded; empty = all
  cv::Rect footprint;                        // photo pixels the mesh can take colour from
};

constexpr int kLutSize = 33;  // equalisation lookup grid per axis (trilinear in between)

// Uploads 8-bit BGR `bgr` with `mask` (CV_8U, empty = 255) as alpha into the RGBA8 texture `tex`
// with linear filtering; image row 0 is t = 0. Allocates only on the first call or a size change
// (else glTexSubImage2D). Images larger than GL_MAX_TEXTURE_SIZE are downscaled (the shader
// samples in normalised coordinates).
void upload_bgr(const cv::Mat& bgr, const cv::Mat& mask, GLuint& tex, cv::Size& allocated);

// An RGBA8 texture of `size` with linear filtering as colour attachment 0 of `fbo`. Throws
// std::runtime_error when the framebuffer is incomplete.
void ensure_target(GLuint& tex, cv::Size& allocated, GLuint& fbo, cv::Size size);

// The equalisation grid (detail::equalize_grid, kLutSize per axis) as a 2D RGBA8 texture.
void upload_lut(const cv::Mat& grid, GLuint& tex);

// Renders `mesh` from `camera` with `depth_prog` (shaders::kSourceDepth*) into source.zmap and
// source.zrange; source.depth is marked stale (read_source_depth reads it when needed).
void render_source_depth(const capture::CameraModel& camera, const gl::GpuMesh& mesh,
                         GLuint depth_prog, SourceGl& source);

// source.depth, read back from source.zmap first when a render_source_depth has not been read
// yet (the context must be current).
const cv::Mat& read_source_depth(SourceGl& source);

// The photo pixels `vertices` project to in `camera` (with distortion), plus a margin for
// bilinear sampling, within the image; empty when none projects.
cv::Rect photo_footprint(const capture::CameraModel& camera,
                         const std::vector<Eigen::Vector3d>& vertices);

}  // namespace orthoface::render::detail
