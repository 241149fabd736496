#include "render/source_textures.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace orthoface::render::detail {

void upload_bgr(const cv::Mat& bgr, const cv::Mat& mask, GLuint& tex, cv::Size& allocated) {
  cv::Mat bgra(bgr.size(), CV_8UC4);
  const cv::Mat alpha = mask.empty() ? cv::Mat(bgr.size(), CV_8U, cv::Scalar(255)) : mask;
  const cv::Mat parts[] = {bgr, alpha};
  const int from_to[] = {0, 0, 1, 1, 2, 2, 3, 3};
  cv::mixChannels(parts, 2, &bgra, 1, from_to, 4);
  cv::Mat image = gl::fit_texture_limit(bgra);
  if (!image.isContinuous()) image = image.clone();
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  if (allocated == image.size()) {
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.cols, image.rows, GL_BGRA, GL_UNSIGNED_BYTE,
                    image.data);
    return;
  }
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.cols, image.rows, 0, GL_BGRA, GL_UNSIGNED_BYTE,
               image.data);
  gl::linear_clamp_parameters();
  allocated = image.size();
}

void ensure_target(GLuint& tex, cv::Size& allocated, GLuint& fbo, cv::Size size) {
  if (tex && allocated == size) return;
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, size.width, size.height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               nullptr);
  gl::linear_clamp_parameters();
  if (!fbo) glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("new view: equalisation framebuffer is incomplete");
  allocated = size;
}

// kLutSize slices side by side (x = b * n + r, y = g): the shader interpolates bilinearly within
// two slices and linearly between them (llvmpipe's 2D unorm8 filtering is far cheaper than its
// 3D path).
void upload_lut(const cv::Mat& grid, GLuint& tex) {
  const int n = kLutSize;
  cv::Mat atlas(n, n * n, CV_32FC3);
  const auto* entry = grid.ptr<cv::Vec3f>();
  for (int b = 0; b < n; ++b)
    for (int g = 0; g < n; ++g)
      for (int r = 0; r < n; ++r) atlas.at<cv::Vec3f>(g, b * n + r) = entry[(b * n + g) * n + r];
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, n * n, n, 0, GL_BGR, GL_FLOAT, atlas.data);
  gl::linear_clamp_parameters();
}

// Linear depth map of the source, (z_cam - near) / (far - near), into a depth texture sampled
// with comparison at the nearest texel (one fetch: 2x2 PCF cost about 1 ms CPU per 640x480
// frame on llvmpipe and changed no PSNR on the sim heads or the scan by 0.1 dB). Back faces
// culled. The texture and its framebuffer are kept while the size stays; the z_cam copy on the
// CPU is read back later, when asked for (read_source_depth).
void render_source_depth(const capture::CameraModel& c, const gl::GpuMesh& mesh, GLuint depth_prog,
                         SourceGl& s) {
  const cv::Size size(c.width, c.height);
  if (!s.zmap || s.zmap_size != size) {
    if (!s.zmap) glGenTextures(1, &s.zmap);
    glBindTexture(GL_TEXTURE_2D, s.zmap);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, c.width, c.height, 0, GL_DEPTH_COMPONENT,
                 GL_FLOAT, nullptr);
    gl::linear_clamp_parameters();
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    if (!s.depth_fbo) glGenFramebuffers(1, &s.depth_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, s.depth_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, s.zmap, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("new view: source depth framebuffer is incomplete");
    s.zmap_size = size;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, s.depth_fbo);
  glViewport(0, 0, c.width, c.height);
  const float one = 1.0f;
  glClearBufferfv(GL_DEPTH, 0, &one);
  s.zrange = gl::near_far(c, mesh.lo, mesh.hi);
  if (s.zrange[1] > s.zrange[0]) {
    const auto clip = gl::clip_from_head(c, s.zrange[0], s.zrange[1]);
    const auto zrow = gl::zcam_row(c);
    glUseProgram(depth_prog);
    glUniformMatrix4fv(glGetUniformLocation(depth_prog, "clip_from_head"), 1, GL_FALSE,
                       clip.data());
    glUniform4fv(glGetUniformLocation(depth_prog, "zrow"), 1, zrow.data());
    glUniform2f(glGetUniformLocation(depth_prog, "zrange"), float(s.zrange[0]), float(s.zrange[1]));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CW);
    glEnable(GL_CULL_FACE);
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  s.depth_stale = true;
}

const cv::Mat& read_source_depth(SourceGl& s) {
  if (!s.depth_stale) return s.depth;
  s.depth.create(s.zmap_size, CV_32F);
  GLint bound = 0;  // e.g. a view being drawn: its framebuffer stays bound for drawing
  glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &bound);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, s.depth_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, s.zmap_size.width, s.zmap_size.height, GL_DEPTH_COMPONENT, GL_FLOAT,
               s.depth.data);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(bound));
  gl::window_depth_to_zcam(s.depth, s.zrange[0], s.zrange[1], false);  // linear by construction
  s.depth_stale = false;
  return s.depth;
}

// The equalisation pass only needs these pixels.
cv::Rect photo_footprint(const capture::CameraModel& c,
                         const std::vector<Eigen::Vector3d>& vertices) {
  constexpr int kMargin = 3;
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (const Eigen::Vector3d& v : vertices) {
    if (c.projection == capture::Projection::Perspective && !(capture::depth(c, v) > 0)) continue;
    const Eigen::Vector2d uv = capture::project(c, v);
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], uv[k]), hi[k] = std::max(hi[k], uv[k]);
  }
  const cv::Rect image(0, 0, c.width, c.height);
  if (!(lo[0] <= hi[0] && lo[1] <= hi[1])) return cv::Rect();
  auto clamped = [](double x, int limit) { return int(std::clamp(x, -1.0, double(limit) + 1)); };
  const cv::Point a(clamped(std::floor(lo[0]), c.width) - kMargin,
                    clamped(std::floor(lo[1]), c.height) - kMargin);
  const cv::Point b(clamped(std::ceil(hi[0]), c.width) + kMargin,
                    clamped(std::ceil(hi[1]), c.height) + kMargin);
  return cv::Rect(a, b) & image;
}

}  // namespace orthoface::render::detail
