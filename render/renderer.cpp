#include "render/renderer.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
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

// MODE (0 grey, 1 vertex colours, 2 texture) and LIT are compile-time: llvmpipe runs both
// sides of a branch, so one program per case draws faster than one with uniform switches.
const char* kFragmentBody = R"(
in vec3 v_n;
in vec3 v_col;
in vec2 v_uv;
uniform int wire;
uniform vec3 wire_color;
uniform sampler2D tex;
uniform vec3 light_dir;
uniform float ambient;
uniform float diffuse;
layout(location = 0) out vec4 color;
void main() {
  if (wire == 1) { color = vec4(wire_color, 1.0); return; }
#if MODE == 2
  vec3 albedo = texture(tex, vec2(v_uv.x, 1.0 - v_uv.y)).rgb;
#elif MODE == 1
  vec3 albedo = v_col;
#else
  vec3 albedo = vec3(0.8);
#endif
#if LIT
  float len = length(v_n);
  vec3 n = len > 0.0 ? v_n / len : vec3(0.0);
  if (!gl_FrontFacing) n = -n;
  float shade = ambient + diffuse * max(0.0, dot(n, -light_dir));
#else
  float shade = ambient;
#endif
  color = vec4(albedo * shade, 1.0);
})";

std::string fragment_source(int mode, bool lit) {
  return "#version 330 core\n#define MODE " + std::to_string(mode) + "\n#define LIT " +
         (lit ? "1" : "0") + "\n" + kFragmentBody;
}

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

MeshKey key_of(const mesh::TriMesh& m) {
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

struct Cached {
  MeshKey key;
  gl::GpuMesh mesh;
  uint64_t last_used = 0;
};

}  // namespace

struct Renderer::Impl {
  gl::Context context;
  GLuint programs[3][2] = {};  // [mesh mode][lit], compiled on first use
  gl::Framebuffer fb;
  std::vector<Cached> cache;
  uint64_t clock = 0;

  ~Impl() {
    context.make_current();
    for (auto& c : cache) c.mesh.release();
    fb.release();
    for (auto& by_lit : programs)
      for (GLuint p : by_lit)
        if (p) glDeleteProgram(p);
  }

  GLuint program_for(int mode, bool lit) {
    GLuint& p = programs[mode][lit];
    if (!p) p = gl::program(kVertex, fragment_source(mode, lit).c_str(), "renderer");
    return p;
  }

  // The cached upload of `m`, uploading (after check_mesh) on a miss.
  const gl::GpuMesh& mesh(const mesh::TriMesh& m) {
    const MeshKey key = key_of(m);
    for (auto& c : cache)
      if (c.key == key) return c.last_used = ++clock, c.mesh;
    mesh::check_mesh(m, "render: mesh");
    if (int(cache.size()) >= kCacheSize) {
      auto oldest = cache.begin();
      for (auto it = cache.begin(); it != cache.end(); ++it)
        if (it->last_used < oldest->last_used) oldest = it;
      oldest->mesh.release();
      cache.erase(oldest);
    }
    cache.push_back({key, gl::upload_mesh(m, true), ++clock});
    return cache.back().mesh;
  }

  // Selects the program for `g` and `o` and sets its uniforms; returns it.
  GLuint uniforms(const gl::GpuMesh& g, const capture::CameraModel& camera,
                  const RenderOptions& o) {
    const auto nf = gl::near_far(camera, g.lo, g.hi);
    const auto clip = gl::clip_from_head(camera, nf[0], nf[1]);
    const Eigen::Vector3d d = o.light.direction_head.normalized();
    const GLuint prog = program_for(g.mode, o.light.diffuse != 0.0);
    glUseProgram(prog);
    glUniformMatrix4fv(glGetUniformLocation(prog, "clip_from_head"), 1, GL_FALSE, clip.data());
    glUniform1i(glGetUniformLocation(prog, "tex"), 0);
    glUniform3f(glGetUniformLocation(prog, "light_dir"), float(d.x()), float(d.y()), float(d.z()));
    glUniform1f(glGetUniformLocation(prog, "ambient"), float(o.light.ambient));
    glUniform1f(glGetUniformLocation(prog, "diffuse"), float(o.light.diffuse));
    glUniform3f(glGetUniformLocation(prog, "wire_color"), float(o.wireframe_color[2] / 255),
                float(o.wireframe_color[1] / 255), float(o.wireframe_color[0] / 255));
    return prog;
  }

  void draw(GLuint prog, const gl::GpuMesh& g, const RenderOptions& o) {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glFrontFace(GL_CW);  // window y = image row: front faces appear clockwise
    if (o.cull_back_faces)
      glEnable(GL_CULL_FACE), glCullFace(GL_BACK);
    else
      glDisable(GL_CULL_FACE);
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
};

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

RenderResult Renderer::render(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                              const RenderOptions& options) {
  if (mesh.vertices.empty() || mesh.triangles.empty())
    throw std::invalid_argument("render: mesh is empty");
  gl::check_camera(camera, "render: camera");
  impl_->context.make_current();
  const gl::GpuMesh& g = impl_->mesh(mesh);
  impl_->fb.ensure(camera.width, camera.height, {GL_RGBA8});
  glBindFramebuffer(GL_FRAMEBUFFER, impl_->fb.fbo);
  glViewport(0, 0, camera.width, camera.height);
  // Alpha 0 outside the mesh: the mask when depth is not read (the shader writes alpha 1).
  const float bg[4] = {float(options.background[2] / 255), float(options.background[1] / 255),
                       float(options.background[0] / 255), 0.0f};
  const float one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, bg);
  glClearBufferfv(GL_DEPTH, 0, &one);
  const auto nf = gl::near_far(camera, g.lo, g.hi);
  if (nf[1] > nf[0]) {
    impl_->draw(impl_->uniforms(g, camera, options), g, options);
  }
  return gl::read_result(camera.width, camera.height, nf,
                         camera.projection == capture::Projection::Perspective, options.read_depth);
}

void Renderer::clear_cache() {
  impl_->context.make_current();
  for (auto& c : impl_->cache) c.mesh.release();
  impl_->cache.clear();
}

int Renderer::cached_meshes() const { return int(impl_->cache.size()); }

RenderResult render_once(const mesh::TriMesh& mesh, const capture::CameraModel& camera,
                         const RenderOptions& options) {
  mesh::check_mesh(mesh, "render: mesh");
  gl::check_camera(camera, "render: camera");
  Renderer renderer;
  return renderer.render(mesh, camera, options);
}

}  // namespace orthoface::render
