#include "render/new_view.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"
#include "render/gl_util.h"

namespace orthoface::render {
namespace {

const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
uniform mat4 clip_from_head;
out vec3 v_p;
out vec3 v_n;
void main() {
  gl_Position = clip_from_head * vec4(pos, 1.0);
  v_p = pos;
  v_n = nrm;
})";

// Source depth maps: z_cam of the nearest front-facing surface.
const char* kDepthFragment = R"(#version 330 core
in vec3 v_p;
in vec3 v_n;
uniform vec4 zrow;
layout(location = 0) out float z;
void main() { z = dot(zrow, vec4(v_p, 1.0)); })";

// Texture inheritance, seed 004 §6: colour from the photo the point faces more (pick) or a
// cosine-weighted mix (weighted), only from photos that see the point.
const char* kViewFragment = R"(#version 330 core
in vec3 v_p;
in vec3 v_n;
struct Source {
  mat4 cam_from_head;
  vec4 intr;    // fx fy cx cy
  vec2 size;    // width height, pixels
  vec4 k;       // k1 k2 p1 p2
  float k3;
  int persp;
  vec3 centre;  // camera centre (perspective), head frame
  vec3 toward;  // -viewing direction (orthographic)
};
uniform Source src[2];
uniform sampler2D photo0;
uniform sampler2D photo1;
uniform sampler2D zmap0;
uniform sampler2D zmap1;
uniform int blend;
uniform float feather;
uniform float power;
uniform float tol_mm;
uniform float vis_px;
uniform vec3 fill;
layout(location = 0) out vec4 color;
layout(location = 1) out vec4 weights;

vec2 pixel(Source s, vec3 pc, bool distort) {
  if (s.persp == 0) return s.intr.zw + s.intr.xy * pc.xy;
  vec2 xy = pc.xy / pc.z;
  if (distort) {  // OpenCV model, as capture::project
    float r2 = dot(xy, xy);
    float radial = 1.0 + r2 * (s.k.x + r2 * (s.k.y + r2 * s.k3));
    xy = xy * radial + vec2(2.0 * s.k.z * xy.x * xy.y + s.k.w * (r2 + 2.0 * xy.x * xy.x),
                            s.k.z * (r2 + 2.0 * xy.y * xy.y) + 2.0 * s.k.w * xy.x * xy.y);
  }
  return s.intr.zw + s.intr.xy * xy;
}

// How much source s sees head point p (0..1), its colour there and the facing cosine.
float look(Source s, sampler2D photo, sampler2D zmap, vec3 p, vec3 n, out vec3 rgb,
           out float cosine) {
  rgb = vec3(0.0);
  vec3 pc = (s.cam_from_head * vec4(p, 1.0)).xyz;
  vec3 toward = s.persp == 1 ? normalize(s.centre - p) : s.toward;
  cosine = dot(n, toward);
  if (cosine <= 0.0 || (s.persp == 1 && pc.z <= 0.0)) return 0.0;
  vec2 uv = pixel(s, pc, true);
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, s.size))) return 0.0;
  vec2 und = pixel(s, pc, false);
  float px_mm = (s.persp == 1 ? pc.z : 1.0) / s.intr.x;
  float tol = tol_mm + 1.5 * px_mm / max(cosine, 0.2);
  const vec2 taps[5] = vec2[5](vec2(0.0), vec2(1.0, 0.0), vec2(-1.0, 0.0), vec2(0.0, 1.0),
                               vec2(0.0, -1.0));
  float seen = 0.0;
  for (int i = 0; i < 5; ++i) {
    float z = texture(zmap, (und + vis_px * taps[i]) / s.size).r;
    seen += pc.z <= z + tol ? 0.2 : 0.0;
  }
  rgb = texture(photo, uv / s.size).rgb;
  return seen * smoothstep(0.0, 0.1, cosine);
}

void main() {
  float len = length(v_n);
  vec3 n = len > 0.0 ? v_n / len : vec3(0.0);
  vec3 c0, c1;
  float cos0, cos1;
  float a0 = look(src[0], photo0, zmap0, v_p, n, c0, cos0);
  float a1 = look(src[1], photo1, zmap1, v_p, n, c1, cos1);
  float pf;  // share of the front photo where both see the point
  if (blend == 0) {
    pf = feather > 0.0 ? smoothstep(-feather, feather, cos0 - cos1) : step(0.0, cos0 - cos1);
  } else {
    float q0 = pow(max(cos0, 0.0), power), q1 = pow(max(cos1, 0.0), power);
    pf = q0 + q1 > 0.0 ? q0 / (q0 + q1) : 0.5;
  }
  float w0 = a0 * (1.0 - a1) + a0 * a1 * pf;
  float w1 = a1 * (1.0 - a0) + a0 * a1 * (1.0 - pf);
  float unseen = (1.0 - a0) * (1.0 - a1);
  color = vec4(w0 * c0 + w1 * c1 + unseen * fill, 1.0);
  weights = vec4(w0, w1, unseen, 1.0);
})";

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
  GLuint zmap = 0, photo = 0, photo_eq = 0;
  cv::Mat depth;  // z_cam, CV_32F
};

}  // namespace

void SynthesisOptions::check() const {
  auto bad = [](const std::string& field) {
    throw std::invalid_argument("new view options: " + field);
  };
  if (!(feather_deg >= 0 && feather_deg <= 45)) bad("feather_deg must be in 0..45");
  if (!(weighted_power > 0 && weighted_power <= 16)) bad("weighted_power must be in (0, 16]");
  if (!(visibility_tolerance_mm >= 0 && visibility_tolerance_mm <= 100))
    bad("visibility_tolerance_mm must be in 0..100");
  if (!(visibility_feather_px >= 0 && visibility_feather_px <= 10))
    bad("visibility_feather_px must be in 0..10");
}

struct ViewSynthesizer::Impl {
  gl::Context context;
  GLuint view_prog = 0, depth_prog = 0;
  gl::GpuMesh mesh;
  std::vector<Eigen::Vector3d> vertices, normals;
  capture::RigCalibration rig;
  SourceGl src[2];
  std::array<cv::Mat, 2> photos;
  ColourMatch match;
  gl::Framebuffer fb;

  Impl() {
    view_prog = gl::program(kVertex, kViewFragment, "new_view");
    depth_prog = gl::program(kVertex, kDepthFragment, "source_depth");
  }
  ~Impl() {
    context.make_current();
    for (auto& s : src) {
      const GLuint tex[3] = {s.zmap, s.photo, s.photo_eq};
      glDeleteTextures(3, tex);
    }
    mesh.release();
    fb.release();
    glDeleteProgram(view_prog);
    glDeleteProgram(depth_prog);
  }

  const capture::CameraModel& cam(int i) const { return i == 0 ? rig.front : rig.side; }
  void render_source_depth(int i);
  void upload_photos();
  void source_uniforms();
};

// z_cam map of source i into a float texture (and a CPU copy), back faces culled.
void ViewSynthesizer::Impl::render_source_depth(int i) {
  const capture::CameraModel& c = cam(i);
  gl::Framebuffer target;
  target.ensure(c.width, c.height, {GL_R32F});
  glViewport(0, 0, c.width, c.height);
  const float inf[4] = {std::numeric_limits<float>::infinity(), 0, 0, 0}, one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, inf);
  glClearBufferfv(GL_DEPTH, 0, &one);
  const auto nf = gl::near_far(c, mesh.lo, mesh.hi);
  if (nf[1] > nf[0]) {
    const auto clip = gl::clip_from_head(c, nf[0], nf[1]);
    const auto zrow = gl::zcam_row(c);
    glUseProgram(depth_prog);
    glUniformMatrix4fv(glGetUniformLocation(depth_prog, "clip_from_head"), 1, GL_FALSE,
                       clip.data());
    glUniform4fv(glGetUniformLocation(depth_prog, "zrow"), 1, zrow.data());
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CW);
    glEnable(GL_CULL_FACE);
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT, nullptr);
    glBindVertexArray(0);
  }
  src[i].depth.create(c.height, c.width, CV_32F);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, c.width, c.height, GL_RED, GL_FLOAT, src[i].depth.data);
  target.release();
  if (!src[i].zmap) glGenTextures(1, &src[i].zmap);
  glBindTexture(GL_TEXTURE_2D, src[i].zmap);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, c.width, c.height, 0, GL_RED, GL_FLOAT,
               src[i].depth.data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// Equalisation statistics from the current mesh and photos, then raw + equalised textures.
void ViewSynthesizer::Impl::upload_photos() {
  match = detail::colour_match(vertices, normals, rig, {src[0].depth, src[1].depth}, photos);
  for (int i = 0; i < 2; ++i) {
    src[i].photo = gl::upload_texture(photos[i], src[i].photo);
    src[i].photo_eq = gl::upload_texture(detail::equalized(photos[i], match, i), src[i].photo_eq);
  }
}

void ViewSynthesizer::Impl::source_uniforms() {
  glUseProgram(view_prog);
  for (int i = 0; i < 2; ++i) {
    const capture::CameraModel& c = cam(i);
    const std::string s = "src[" + std::to_string(i) + "].";
    auto loc = [&](const char* name) { return glGetUniformLocation(view_prog, (s + name).c_str()); };
    Eigen::Matrix4f m = c.cam_from_head.matrix().cast<float>();
    glUniformMatrix4fv(loc("cam_from_head"), 1, GL_FALSE, m.data());
    glUniform4f(loc("intr"), float(c.fx), float(c.fy), float(c.cx), float(c.cy));
    glUniform2f(loc("size"), float(c.width), float(c.height));
    double k[5] = {0, 0, 0, 0, 0};
    for (size_t j = 0; j < c.distortion.size() && j < 5; ++j) k[j] = c.distortion[j];
    glUniform4f(loc("k"), float(k[0]), float(k[1]), float(k[2]), float(k[3]));
    glUniform1f(loc("k3"), float(k[4]));
    glUniform1i(loc("persp"), c.projection == capture::Projection::Perspective ? 1 : 0);
    const Eigen::Vector3f centre = c.cam_from_head.inverse().translation().cast<float>();
    const Eigen::Vector3f toward = (-capture::view_direction(c)).cast<float>();
    glUniform3f(loc("centre"), centre.x(), centre.y(), centre.z());
    glUniform3f(loc("toward"), toward.x(), toward.y(), toward.z());
  }
  const char* samplers[4] = {"photo0", "photo1", "zmap0", "zmap1"};
  for (int t = 0; t < 4; ++t) glUniform1i(glGetUniformLocation(view_prog, samplers[t]), t);
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
  impl_->source_uniforms();
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
    const GLuint p = m.view_prog;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "clip_from_head"), 1, GL_FALSE, clip.data());
    glUniform1i(glGetUniformLocation(p, "blend"), o.blend == Blend::Pick ? 0 : 1);
    // cos0 - cos1 changes by sqrt(2) per radian of normal rotation near the 45-degree switch.
    glUniform1f(glGetUniformLocation(p, "feather"), float(std::sqrt(2.0) * o.feather_deg * M_PI / 180));
    glUniform1f(glGetUniformLocation(p, "power"), float(o.weighted_power));
    glUniform1f(glGetUniformLocation(p, "tol_mm"), float(o.visibility_tolerance_mm));
    glUniform1f(glGetUniformLocation(p, "vis_px"), float(o.visibility_feather_px));
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
