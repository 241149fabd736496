#include "render/renderer.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/gl_util.h"

namespace orthoface::render {
namespace {

const char* kVertex = R"(#version 330 core
layout(location = 0) in vec3 pos;
layout(location = 1) in vec3 nrm;
layout(location = 2) in vec3 col;
layout(location = 3) in vec2 uv;
uniform mat4 clip_from_head;
out vec3 v_n;
out vec3 v_col;
out vec2 v_uv;
void main() {
  gl_Position = clip_from_head * vec4(pos, 1.0);
  v_n = nrm;
  v_col = col;
  v_uv = uv;
})";

const char* kFragment = R"(#version 330 core
in vec3 v_n;
in vec3 v_col;
in vec2 v_uv;
uniform int mode;  // 0 grey, 1 vertex colours, 2 texture
uniform int wire;
uniform vec3 wire_color;
uniform sampler2D tex;
uniform vec3 light_dir;
uniform float ambient;
uniform float diffuse;
layout(location = 0) out vec4 color;
void main() {
  if (wire == 1) { color = vec4(wire_color, 1.0); return; }
  vec3 albedo = mode == 2 ? texture(tex, vec2(v_uv.x, 1.0 - v_uv.y)).rgb
              : (mode == 1 ? v_col : vec3(0.8));
  float len = length(v_n);
  vec3 n = len > 0.0 ? v_n / len : vec3(0.0);
  if (!gl_FrontFacing) n = -n;
  float shade = ambient + diffuse * max(0.0, dot(n, -light_dir));
  color = vec4(albedo * shade, 1.0);
})";

constexpr int kCacheSize = 8;

// Identity of a mesh's contents as seen by the cache.
struct MeshKey {
  const void* ptr[5] = {};
  size_t size[5] = {};
  int tex_rows = 0, tex_cols = 0;
  uint64_t hash = 0;
  bool operator==(const MeshKey& o) const {
    return std::memcmp(ptr, o.ptr, sizeof(ptr)) == 0 &&
           std::memcmp(size, o.size, sizeof(size)) == 0 && tex_rows == o.tex_rows &&
           tex_cols == o.tex_cols && hash == o.hash;
  }
};

uint64_t mix(uint64_t h, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  size_t i = 0;
  for (; i + 8 <= bytes; i += 8) {
    uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 0x9E3779B97F4A7C15ULL;
    h ^= h >> 29;
  }
  for (; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001B3ULL;
  return h;
}

MeshKey key_of(const model::TriMesh& m) {
  MeshKey k;
  const void* ptrs[5] = {m.vertices.data(), m.triangles.data(), m.uvs.data(), m.colors.data(),
                         m.texture.data};
  const size_t sizes[5] = {m.vertices.size(), m.triangles.size(), m.uvs.size(), m.colors.size(),
                           m.texture.total() * m.texture.elemSize()};
  std::memcpy(k.ptr, ptrs, sizeof(ptrs));
  std::memcpy(k.size, sizes, sizeof(sizes));
  k.tex_rows = m.texture.rows;
  k.tex_cols = m.texture.cols;
  uint64_t h = 1469598103934665603ULL;
  h = mix(h, m.vertices.data(), m.vertices.size() * sizeof(Eigen::Vector3d));
  h = mix(h, m.triangles.data(), m.triangles.size() * sizeof(std::array<int, 3>));
  h = mix(h, m.uvs.data(), m.uvs.size() * sizeof(Eigen::Vector2d));
  h = mix(h, m.colors.data(), m.colors.size() * sizeof(Eigen::Vector3d));
  if (!m.texture.empty() && m.texture.isContinuous()) {  // sampled: 4096 texels
    const size_t n = sizes[4], step = std::max<size_t>(1, n / 4096);
    for (size_t i = 0; i < n; i += step) h = (h ^ m.texture.data[i]) * 0x100000001B3ULL;
  }
  k.hash = h;
  return k;
}

struct GpuMesh {
  MeshKey key;
  GLuint vao = 0, vbo = 0, ebo = 0, tex = 0;
  GLsizei count = 0;
  int mode = 0;
  Eigen::Vector3d lo, hi;
  uint64_t last_used = 0;

  void release() {
    if (tex) glDeleteTextures(1, &tex);
    if (ebo) glDeleteBuffers(1, &ebo);
    if (vbo) glDeleteBuffers(1, &vbo);
    if (vao) glDeleteVertexArrays(1, &vao);
    tex = ebo = vbo = vao = 0;
  }
};

// Interleaved vertex buffer: position, normal, colour, uv (11 floats per vertex).
GpuMesh upload(const model::TriMesh& m) {
  GpuMesh g;
  g.mode = (!m.texture.empty() && !m.uvs.empty()) ? 2 : (!m.colors.empty() ? 1 : 0);
  const auto normals = gl::vertex_normals(m);
  std::vector<float> data(m.vertices.size() * 11, 0.0f);
  g.lo = g.hi = m.vertices[0];
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    float* d = &data[i * 11];
    for (int k = 0; k < 3; ++k) {
      d[k] = float(m.vertices[i][k]);
      d[3 + k] = float(normals[i][k]);
      d[6 + k] = m.colors.empty() ? 0.8f : float(m.colors[i][k]);
    }
    if (!m.uvs.empty()) d[9] = float(m.uvs[i].x()), d[10] = float(m.uvs[i].y());
    g.lo = g.lo.cwiseMin(m.vertices[i]);
    g.hi = g.hi.cwiseMax(m.vertices[i]);
  }
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  glGenBuffers(1, &g.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, g.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(),
               GL_STATIC_DRAW);
  const int offsets[4] = {0, 3, 6, 9}, sizes[4] = {3, 3, 3, 2};
  for (int a = 0; a < 4; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, 11 * sizeof(float),
                          reinterpret_cast<void*>(offsets[a] * sizeof(float)));
  }
  glGenBuffers(1, &g.ebo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.triangles.size() * 3 * sizeof(int)),
               m.triangles.data(), GL_STATIC_DRAW);
  g.count = GLsizei(m.triangles.size() * 3);
  glBindVertexArray(0);
  if (g.mode == 2) g.tex = gl::upload_texture(m.texture, 0);
  return g;
}

}  // namespace

struct Renderer::Impl {
  gl::Context context;
  GLuint prog = 0;
  gl::Framebuffer fb;
  std::vector<GpuMesh> cache;
  uint64_t clock = 0;

  Impl() {
    prog = gl::program(kVertex, kFragment, "renderer");
  }
  ~Impl() {
    context.make_current();
    for (auto& g : cache) g.release();
    fb.release();
    glDeleteProgram(prog);
  }

  // The cached upload of `m`, uploading (after check_mesh) on a miss.
  GpuMesh& mesh(const model::TriMesh& m) {
    const MeshKey key = key_of(m);
    for (auto& g : cache)
      if (g.key == key) return g.last_used = ++clock, g;
    model::check_mesh(m, "render: mesh");
    if (int(cache.size()) >= kCacheSize) {
      auto oldest = cache.begin();
      for (auto it = cache.begin(); it != cache.end(); ++it)
        if (it->last_used < oldest->last_used) oldest = it;
      oldest->release();
      cache.erase(oldest);
    }
    cache.push_back(upload(m));
    cache.back().key = key;
    cache.back().last_used = ++clock;
    return cache.back();
  }

  void uniforms(const GpuMesh& g, const capture::CameraModel& camera,
                const RenderOptions& o) {
    const auto nf = gl::near_far(camera, g.lo, g.hi);
    const auto clip = gl::clip_from_head(camera, nf[0], nf[1]);
    const Eigen::Vector3d d = o.light.direction_head.normalized();
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "clip_from_head"), 1, GL_FALSE, clip.data());
    glUniform1i(glGetUniformLocation(prog, "mode"), g.mode);
    glUniform1i(glGetUniformLocation(prog, "tex"), 0);
    glUniform3f(glGetUniformLocation(prog, "light_dir"), float(d.x()), float(d.y()),
                float(d.z()));
    glUniform1f(glGetUniformLocation(prog, "ambient"), float(o.light.ambient));
    glUniform1f(glGetUniformLocation(prog, "diffuse"), float(o.light.diffuse));
    glUniform3f(glGetUniformLocation(prog, "wire_color"), float(o.wireframe_color[2] / 255),
                float(o.wireframe_color[1] / 255), float(o.wireframe_color[0] / 255));
  }

  void draw(const GpuMesh& g, const RenderOptions& o) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glFrontFace(GL_CW);  // window y = image row: front faces appear clockwise
    if (o.cull_back_faces) glEnable(GL_CULL_FACE), glCullFace(GL_BACK);
    else glDisable(GL_CULL_FACE);
    glBindVertexArray(g.vao);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g.tex);
    glUniform1i(glGetUniformLocation(prog, "wire"), 0);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDrawElements(GL_TRIANGLES, g.count, GL_UNSIGNED_INT, nullptr);
    if (o.wireframe) {
      glEnable(GL_POLYGON_OFFSET_LINE);  // lines pulled toward the camera; depth kept exact
      glPolygonOffset(-1.0f, -1.0f);
      glDepthFunc(GL_LEQUAL);
      glDepthMask(GL_FALSE);
      glUniform1i(glGetUniformLocation(prog, "wire"), 1);
      glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      glDrawElements(GL_TRIANGLES, g.count, GL_UNSIGNED_INT, nullptr);
      glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
      glDisable(GL_POLYGON_OFFSET_LINE);
      glDepthMask(GL_TRUE);
    }
    glBindVertexArray(0);
  }

  RenderResult read(int w, int h, const std::array<double, 2>& nf, bool perspective) {
    RenderResult r;
    cv::Mat bgra(h, w, CV_8UC4);
    r.depth_mm.create(h, w, CV_32F);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data);
    glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, r.depth_mm.data);
    cv::cvtColor(bgra, r.image, cv::COLOR_BGRA2BGR);
    r.mask = r.depth_mm < 1.0f;
    gl::window_depth_to_zcam(r.depth_mm, nf[0], nf[1], perspective);
    return r;
  }
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

RenderResult Renderer::render(const model::TriMesh& mesh, const capture::CameraModel& camera,
                              const RenderOptions& options) {
  if (mesh.vertices.empty() || mesh.triangles.empty())
    throw std::invalid_argument("render: mesh is empty");
  gl::check_camera(camera, "render: camera");
  impl_->context.make_current();
  const GpuMesh& g = impl_->mesh(mesh);
  impl_->fb.ensure(camera.width, camera.height, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fb.fbo);
  glViewport(0, 0, camera.width, camera.height);
  const float bg[4] = {float(options.background[2] / 255), float(options.background[1] / 255),
                       float(options.background[0] / 255), 1.0f};
  const float one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, bg);
  glClearBufferfv(GL_DEPTH, 0, &one);
  const auto nf = gl::near_far(camera, g.lo, g.hi);
  if (nf[1] > nf[0]) {
    impl_->uniforms(g, camera, options);
    impl_->draw(g, options);
  }
  return impl_->read(camera.width, camera.height, nf,
                     camera.projection == capture::Projection::Perspective);
}

void Renderer::clear_cache() {
  impl_->context.make_current();
  for (auto& g : impl_->cache) g.release();
  impl_->cache.clear();
}

int Renderer::cached_meshes() const { return int(impl_->cache.size()); }

RenderResult render_once(const model::TriMesh& mesh, const capture::CameraModel& camera,
                         const RenderOptions& options) {
  model::check_mesh(mesh, "render: mesh");
  gl::check_camera(camera, "render: camera");
  Renderer renderer;
  return renderer.render(mesh, camera, options);
}

}  // namespace orthoface::render
