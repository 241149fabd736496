#include "render/new_view.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"
#include "render/gl_util.h"
#include "render/new_view_shaders.h"

namespace orthoface::render {
namespace {

cv::Mat as_bgr(const cv::Mat& photo, const capture::CameraModel& cam, const std::string& what) {
  if (photo.empty()) throw std::invalid_argument("new view: " + what + " photo is empty");
  if (photo.depth() != CV_8U || (photo.channels() != 3 && photo.channels() != 1))
    throw std::invalid_argument("new view: " + what + " photo must be 8-bit BGR or grey");
  if (photo.cols != cam.width || photo.rows != cam.height)
    throw std::invalid_argument("new view: " + what + " photo is " + std::to_string(photo.cols) +
                                "x" + std::to_string(photo.rows) + " but its camera is " +
                                std::to_string(cam.width) + "x" + std::to_string(cam.height));
  cv::Mat bgr;
  if (photo.channels() == 1) cv::cvtColor(photo, bgr, cv::COLOR_GRAY2BGR);
  else bgr = photo;
  return bgr;
}

struct SourceGl {
  GLuint zmap = 0, photo = 0, photo_eq = 0;  // zmap: linear depth texture, compare mode
  std::array<double, 2> zrange{0, 0};        // near, far of zmap
  cv::Mat depth;                             // z_cam (mm), CV_32F, +inf where empty
};

std::string view_fragment(bool per_pixel) {
  return std::string("#version 330 core\n") +
         (per_pixel ? "#define PER_PIXEL_VISIBILITY 1\n" : "") + shaders::kViewFragment;
}

}  // namespace

void SynthesisOptions::check() const {
  auto bad = [](const std::string& field) {
    throw std::invalid_argument("new view options: " + field);
  };
  if (!(feather_deg >= 0 && feather_deg <= 45)) bad("feather_deg must be in 0..45");
  if (!(weighted_power > 0 && weighted_power <= 16)) bad("weighted_power must be in (0, 16]");
  if (!(visibility_tolerance_mm >= 0 && visibility_tolerance_mm <= 100))
    bad("visibility_tolerance_mm must be in 0..100");
}

struct ViewSynthesizer::Impl {
  gl::Context context;
  GLuint view_prog[2] = {0, 0};  // [0] per-vertex, [1] per-pixel visibility
  GLuint depth_prog = 0;
  gl::GpuMesh mesh;
  GLuint seen_vbo = 0;  // per-vertex visibility in each source (attribute 4)
  std::vector<Eigen::Vector3d> vertices, normals;
  capture::RigCalibration rig;
  SourceGl src[2];
  std::array<cv::Mat, 2> photos;
  ColourMatch match;
  gl::Framebuffer fb;

  Impl() {
    for (int v = 0; v < 2; ++v)
      view_prog[v] = gl::program(shaders::kViewVertex, view_fragment(v == 1).c_str(), "new_view");
    depth_prog = gl::program(shaders::kSourceDepthVertex, shaders::kSourceDepthFragment,
                             "source_depth");
  }
  ~Impl() {
    context.make_current();
    for (auto& s : src) {
      const GLuint tex[3] = {s.zmap, s.photo, s.photo_eq};
      glDeleteTextures(3, tex);
    }
    if (seen_vbo) glDeleteBuffers(1, &seen_vbo);
    mesh.release();
    fb.release();
    for (GLuint p : view_prog) glDeleteProgram(p);
    glDeleteProgram(depth_prog);
  }

  const capture::CameraModel& cam(int i) const { return i == 0 ? rig.front : rig.side; }
  void render_source_depth(int i);
  void upload_seen();
  void upload_photos();
  void source_uniforms(GLuint prog);
};

// Linear depth map of source i, (z_cam - near) / (far - near), into a depth texture sampled
// with comparison (2x2 PCF), plus its z_cam copy on the CPU. Back faces culled.
void ViewSynthesizer::Impl::render_source_depth(int i) {
  const capture::CameraModel& c = cam(i);
  SourceGl& s = src[i];
  if (!s.zmap) glGenTextures(1, &s.zmap);
  glBindTexture(GL_TEXTURE_2D, s.zmap);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT32F, c.width, c.height, 0, GL_DEPTH_COMPONENT,
               GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, s.zmap, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
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
    glUniform2f(glGetUniformLocation(depth_prog, "zrange"), float(s.zrange[0]),
                float(s.zrange[1]));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CW);
    glEnable(GL_CULL_FACE);
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
  }
  s.depth.create(c.height, c.width, CV_32F);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, c.width, c.height, GL_DEPTH_COMPONENT, GL_FLOAT, s.depth.data);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);
  gl::window_depth_to_zcam(s.depth, s.zrange[0], s.zrange[1], false);  // linear by construction
}

// Per-vertex visibility in each source (the fast path's occlusion test), attribute 4.
void ViewSynthesizer::Impl::upload_seen() {
  std::vector<float> seen(vertices.size() * 2);
  for (size_t v = 0; v < vertices.size(); ++v)
    for (int i = 0; i < 2; ++i) {
      const double cosine = detail::facing(cam(i), vertices[v], normals[v]);
      seen[2 * v + i] = detail::source_sees(cam(i), src[i].depth, vertices[v], cosine, 1.0);
    }
  glBindVertexArray(mesh.vao);
  if (!seen_vbo) glGenBuffers(1, &seen_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, seen_vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(seen.size() * sizeof(float)), seen.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(4);
  glVertexAttribPointer(4, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindVertexArray(0);
}

// Equalisation statistics from the current mesh and photos, then raw + equalised textures.
void ViewSynthesizer::Impl::upload_photos() {
  match = detail::colour_match(vertices, normals, rig, {src[0].depth, src[1].depth}, photos);
  for (int i = 0; i < 2; ++i) {
    src[i].photo = gl::upload_texture(photos[i], src[i].photo);
    src[i].photo_eq = gl::upload_texture(detail::equalized(photos[i], match, i), src[i].photo_eq);
  }
}

// Uniforms that depend only on the rig and the source depth maps.
void ViewSynthesizer::Impl::source_uniforms(GLuint prog) {
  glUseProgram(prog);
  auto loc = [&](const std::string& name) { return glGetUniformLocation(prog, name.c_str()); };
  for (int i = 0; i < 2; ++i) {
    const capture::CameraModel& c = cam(i);
    const std::string at = "[" + std::to_string(i) + "]";
    const Eigen::Matrix4f m = c.cam_from_head.matrix().cast<float>();
    glUniformMatrix4fv(loc("src_from_head" + at), 1, GL_FALSE, m.data());
    glUniform4f(loc("intr" + at), float(c.fx), float(c.fy), float(c.cx), float(c.cy));
    glUniform2f(loc("size" + at), float(c.width), float(c.height));
    double k[5] = {0, 0, 0, 0, 0};
    if (c.projection == capture::Projection::Perspective)
      for (size_t j = 0; j < c.distortion.size() && j < 5; ++j) k[j] = c.distortion[j];
    glUniform4f(loc("dist" + at), float(k[0]), float(k[1]), float(k[2]), float(k[3]));
    glUniform1f(loc("k3" + at), float(k[4]));
    glUniform1i(loc("persp" + at), c.projection == capture::Projection::Perspective ? 1 : 0);
    const Eigen::Vector3f centre = c.cam_from_head.inverse().translation().cast<float>();
    const Eigen::Vector3f toward = (-capture::view_direction(c)).cast<float>();
    glUniform3f(loc("centre" + at), centre.x(), centre.y(), centre.z());
    glUniform3f(loc("toward" + at), toward.x(), toward.y(), toward.z());
    glUniform2f(loc("zrange" + at), float(src[i].zrange[0]), float(src[i].zrange[1]));
  }
  const char* samplers[4] = {"photo0", "photo1", "zmap0", "zmap1"};
  for (int t = 0; t < 4; ++t) glUniform1i(loc(samplers[t]), t);
}

ViewSynthesizer::ViewSynthesizer(const model::TriMesh& mesh, const capture::RigCalibration& rig,
                                 const cv::Mat& front, const cv::Mat& side) {
  gl::check_camera(rig.front, "new view: front camera");
  gl::check_camera(rig.side, "new view: side camera");
  as_bgr(front, rig.front, "front");
  as_bgr(side, rig.side, "side");
  model::check_mesh(mesh, "new view: mesh");
  impl_ = std::make_unique<Impl>();
  impl_->rig = rig;
  set_mesh(mesh);
  set_photos(front, side);
}

ViewSynthesizer::~ViewSynthesizer() = default;

void ViewSynthesizer::set_mesh(const model::TriMesh& mesh) {
  model::check_mesh(mesh, "new view: mesh");
  impl_->context.make_current();
  impl_->mesh.release();
  impl_->mesh = gl::upload_mesh(mesh, false);
  impl_->vertices = mesh.vertices;
  impl_->normals = gl::vertex_normals(mesh);
  for (int i = 0; i < 2; ++i) impl_->render_source_depth(i);
  impl_->upload_seen();
  for (GLuint p : impl_->view_prog) impl_->source_uniforms(p);
  if (!impl_->photos[0].empty()) impl_->upload_photos();
}

void ViewSynthesizer::set_photos(const cv::Mat& front, const cv::Mat& side) {
  impl_->photos = {as_bgr(front, impl_->rig.front, "front"),
                   as_bgr(side, impl_->rig.side, "side")};
  impl_->context.make_current();
  impl_->upload_photos();
}

const ColourMatch& ViewSynthesizer::colour_match() const { return impl_->match; }

cv::Mat ViewSynthesizer::source_depth(int source) const {
  if (source != 0 && source != 1)
    throw std::invalid_argument("new view: source must be 0 (front) or 1 (side), got " +
                                std::to_string(source));
  return impl_->src[source].depth.clone();
}

SynthesisResult ViewSynthesizer::render(const capture::CameraModel& camera,
                                        const SynthesisOptions& o) {
  o.check();
  gl::check_camera(camera, "new view: camera");
  Impl& m = *impl_;
  m.context.make_current();
  m.fb.ensure(camera.width, camera.height, {GL_RGBA8, GL_RGBA8});
  const GLenum bufs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, bufs);
  glViewport(0, 0, camera.width, camera.height);
  const float bg[4] = {float(o.background[2] / 255), float(o.background[1] / 255),
                       float(o.background[0] / 255), 1.0f};
  const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, bg);
  glClearBufferfv(GL_COLOR, 1, zero);
  glClearBufferfv(GL_DEPTH, 0, &one);
  glDrawBuffers(o.source_weights ? 2 : 1, bufs);
  const auto nf = gl::near_far(camera, m.mesh.lo, m.mesh.hi);
  if (nf[1] > nf[0]) {
    const auto clip = gl::clip_from_head(camera, nf[0], nf[1]);
    const GLuint p = m.view_prog[o.per_pixel_visibility ? 1 : 0];
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "clip_from_head"), 1, GL_FALSE, clip.data());
    glUniform1i(glGetUniformLocation(p, "blend"), o.blend == Blend::Pick ? 0 : 1);
    // cos0 - cos1 changes by sqrt(2) per radian of normal rotation near the 45-degree switch.
    glUniform1f(glGetUniformLocation(p, "feather"), float(std::sqrt(2.0) * o.feather_deg * M_PI / 180));
    glUniform1f(glGetUniformLocation(p, "power"), float(o.weighted_power));
    glUniform1f(glGetUniformLocation(p, "tol_mm"), float(o.visibility_tolerance_mm));
    glUniform3f(glGetUniformLocation(p, "fill"), m.match.fill[2] / 255.0f,
                m.match.fill[1] / 255.0f, m.match.fill[0] / 255.0f);
    const GLuint tex[4] = {o.equalize ? m.src[0].photo_eq : m.src[0].photo,
                           o.equalize ? m.src[1].photo_eq : m.src[1].photo, m.src[0].zmap,
                           m.src[1].zmap};
    for (int t = 0; t < 4; ++t) {
      glActiveTexture(GLenum(GL_TEXTURE0 + t));
      glBindTexture(GL_TEXTURE_2D, tex[t]);
    }
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CW);  // window y = image row (see gl::clip_from_head)
    glEnable(GL_CULL_FACE);
    glBindVertexArray(m.mesh.vao);
    glDrawElements(GL_TRIANGLES, m.mesh.count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
  }
  SynthesisResult r;
  r.view = gl::read_result(camera.width, camera.height, nf,
                           camera.projection == capture::Projection::Perspective);
  if (o.source_weights) {
    r.weights.create(camera.height, camera.width, CV_8UC3);
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    glReadPixels(0, 0, camera.width, camera.height, GL_RGB, GL_UNSIGNED_BYTE, r.weights.data);
  }
  return r;
}

SynthesisResult synthesize_view(const model::TriMesh& mesh, const capture::RigCalibration& rig,
                                const cv::Mat& front, const cv::Mat& side,
                                const capture::CameraModel& camera,
                                const SynthesisOptions& options) {
  options.check();
  gl::check_camera(camera, "new view: camera");
  ViewSynthesizer synthesizer(mesh, rig, front, side);
  return synthesizer.render(camera, options);
}

}  // namespace orthoface::render
