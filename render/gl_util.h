#pragma once

// Internal to render/: the OSMesa context, shader and framebuffer helpers, and the camera
// matrices shared by Renderer and ViewSynthesizer (and the reference run in bench/render_bench).

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>  // first: it includes GL/gl.h, which GL/glext.h needs

#include <GL/glext.h>

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "capture/camera_model.h"
#include "mesh/tri_mesh.h"
#include "render/renderer.h"

namespace orthoface::render::gl {

constexpr int kMaxImageSize = kMaxRenderSize;

// One OSMesa core-profile (3.3) context with a 1x1 default buffer; drawing goes to FBOs.
// Throws std::runtime_error naming libOSMesa when no context can be created.
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  void make_current();  // cheap when already current

 private:
  OSMesaContext ctx_ = nullptr;
  std::vector<unsigned char> buffer_;
};

// Compiles and links a GLSL program; throws std::runtime_error with the info log.
GLuint program(const char* vertex_src, const char* fragment_src, const std::string& name);

// An FBO with colour renderbuffers of the given internal formats (GL_RGBA8, GL_R32F, ...)
// and a 32F depth buffer; all colour targets are enabled for drawing.
struct Framebuffer {
  GLuint fbo = 0, depth = 0;
  std::vector<GLuint> colors;
  std::vector<GLenum> formats;
  int width = 0, height = 0;
  void ensure(int w, int h,
              const std::vector<GLenum>& color_formats);  // binds; reallocates on change
  void release();
};

// A mesh in GL buffers. Attributes: 0 position, 1 normal (head frame), 2 colour, 3 uv
// (11 interleaved floats per vertex). mode: 0 grey, 1 vertex colours, 2 texture (in tex).
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0, tex = 0;
  GLsizei count = 0;
  int mode = 0;
  Eigen::Vector3d lo, hi;  // bounding box, head frame
  void release();
};
GpuMesh upload_mesh(const mesh::TriMesh& mesh, bool with_texture);

// Reads colour attachment 0 (as BGR) and the depth buffer (as z_cam mm, +inf where empty, and
// the mask) of the bound framebuffer, w x h, drawn with near_far() planes `nf`. Without depth
// the mask is the colour's alpha: the framebuffer must be cleared to alpha 0 and drawn with 1.
RenderResult read_result(int w, int h, const std::array<double, 2>& nf, bool perspective,
                         bool with_depth = true);

// Throws std::invalid_argument (prefixed by `what`) when the camera's size is outside
// 1..kMaxImageSize or its intrinsics are not positive / finite.
void check_camera(const capture::CameraModel& camera, const std::string& what);

// Near / far z_cam planes (mm) that enclose the axis-aligned box [lo, hi] (head frame) seen by
// `camera`, with a margin; for perspective near > 0. Returns {0, 0} when the box is behind it.
std::array<double, 2> near_far(const capture::CameraModel& camera, const Eigen::Vector3d& lo,
                               const Eigen::Vector3d& hi);

// Clip-space matrix (column-major floats for glUniformMatrix4fv) from head-frame points for
// `camera`: a head point lands in GL window coordinates exactly at capture::project's pixel
// position (distortion ignored), with GL window row 0 = image row 0 (upside down in GL, so the
// readback is already top-left origin and front faces wind clockwise in window space).
std::array<float, 16> clip_from_head(const capture::CameraModel& camera, double near_mm,
                                     double far_mm);

// In place: GL window depth (0..1, from a near_far / clip_from_head projection) to z_cam in mm;
// 1.0 (cleared, nothing drawn) becomes +infinity. `depth` is CV_32F. With `mask`, also writes
// 255 where something was drawn, 0 elsewhere (CV_8U, same size). One pass on the calling thread.
void window_depth_to_zcam(cv::Mat& depth, double near_mm, double far_mm, bool perspective,
                          cv::Mat* mask = nullptr);

// Row 3 of cam_from_head: dot(row, (p_head, 1)) = z_cam.
std::array<float, 4> zcam_row(const capture::CameraModel& camera);

// Uploads an 8-bit BGR (or BGRA) image as an RGBA texture with linear filtering; image row 0
// becomes t = 0. Reuses `tex` when non-zero. Large images are downscaled to the GL limit.
GLuint upload_texture(const cv::Mat& bgr, GLuint tex);

// `image`, downscaled (INTER_AREA) when a side exceeds GL_MAX_TEXTURE_SIZE, else itself.
cv::Mat fit_texture_limit(const cv::Mat& image);

// Bilinear filtering and edge clamping for the bound 2D texture.
void linear_clamp_parameters();

// Per-vertex area-weighted normals (unit; zero for isolated vertices).
std::vector<Eigen::Vector3d> vertex_normals(const mesh::TriMesh& mesh);

}  // namespace orthoface::render::gl
