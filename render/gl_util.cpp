#include "render/gl_util.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace orthoface::render::gl {

Context::Context() : buffer_(4, 0) {
  const int core[] = {OSMESA_FORMAT,
                      OSMESA_RGBA,
                      OSMESA_DEPTH_BITS,
                      24,
                      OSMESA_PROFILE,
                      OSMESA_CORE_PROFILE,
                      OSMESA_CONTEXT_MAJOR_VERSION,
                      3,
                      OSMESA_CONTEXT_MINOR_VERSION,
                      3,
                      0};
  ctx_ = OSMesaCreateContextAttribs(core, nullptr);
  if (!ctx_)
    throw std::runtime_error(
        "cannot create an OpenGL 3.3 core context with libOSMesa (package libosmesa6, Mesa "
        ">= 20 with llvmpipe); is libOSMesa.so installed and working?");
  if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    OSMesaDestroyContext(ctx_);
    ctx_ = nullptr;
    throw std::runtime_error("libOSMesa (libosmesa6): OSMesaMakeCurrent failed");
  }
}

Context::~Context() {
  if (ctx_) OSMesaDestroyContext(ctx_);
}

void Context::make_current() {
  if (OSMesaGetCurrentContext() == ctx_) return;
  if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, 1, 1))
    throw std::runtime_error("libOSMesa (libosmesa6): OSMesaMakeCurrent failed");
}

namespace {

GLuint shader(GLenum type, const char* src, const std::string& name) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {0};
    glGetShaderInfoLog(s, sizeof(log) - 1, nullptr, log);
    glDeleteShader(s);
    throw std::runtime_error("render: shader '" + name + "' does not compile: " + log);
  }
  return s;
}

}  // namespace

GLuint program(const char* vertex_src, const char* fragment_src, const std::string& name) {
  const GLuint vs = shader(GL_VERTEX_SHADER, vertex_src, name + ".vert");
  const GLuint fs = shader(GL_FRAGMENT_SHADER, fragment_src, name + ".frag");
  const GLuint p = glCreateProgram();
  glAttachShader(p, vs);
  glAttachShader(p, fs);
  glLinkProgram(p);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {0};
    glGetProgramInfoLog(p, sizeof(log) - 1, nullptr, log);
    glDeleteProgram(p);
    throw std::runtime_error("render: program '" + name + "' does not link: " + log);
  }
  return p;
}

void Framebuffer::ensure(int w, int h, const std::vector<GLenum>& color_formats) {
  if (fbo && w == width && h == height && formats == color_formats) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    return;
  }
  release();
  width = w;
  height = h;
  formats = color_formats;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  colors.assign(formats.size(), 0);
  glGenRenderbuffers(GLsizei(colors.size()), colors.data());
  std::vector<GLenum> draw;
  for (size_t i = 0; i < colors.size(); ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, colors[i]);
    glRenderbufferStorage(GL_RENDERBUFFER, formats[i], w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_RENDERBUFFER,
                              colors[i]);
    draw.push_back(GLenum(GL_COLOR_ATTACHMENT0 + i));
  }
  glGenRenderbuffers(1, &depth);
  glBindRenderbuffer(GL_RENDERBUFFER, depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
  glDrawBuffers(GLsizei(draw.size()), draw.data());
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    release();
    throw std::runtime_error("render: framebuffer of " + std::to_string(w) + "x" +
                             std::to_string(h) + " is incomplete (libOSMesa limits?)");
  }
}

void Framebuffer::release() {
  if (!colors.empty()) glDeleteRenderbuffers(GLsizei(colors.size()), colors.data());
  if (depth) glDeleteRenderbuffers(1, &depth);
  if (fbo) glDeleteFramebuffers(1, &fbo);
  colors.clear();
  formats.clear();
  fbo = depth = 0;
  width = height = 0;
}

void check_camera(const capture::CameraModel& c, const std::string& what) {
  if (c.width <= 0 || c.height <= 0 || c.width > kMaxImageSize || c.height > kMaxImageSize)
    throw std::invalid_argument(what + ": image size " + std::to_string(c.width) + "x" +
                                std::to_string(c.height) + " is outside 1.." +
                                std::to_string(kMaxImageSize));
  if (!(c.fx > 0) || !(c.fy > 0) || !std::isfinite(c.fx) || !std::isfinite(c.fy) ||
      !std::isfinite(c.cx) || !std::isfinite(c.cy) || !c.cam_from_head.matrix().allFinite())
    throw std::invalid_argument(what + ": camera needs finite fx, fy > 0, cx, cy and pose");
}

std::array<double, 2> near_far(const capture::CameraModel& camera, const Eigen::Vector3d& lo,
                               const Eigen::Vector3d& hi) {
  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                            i & 4 ? hi.z() : lo.z());
    const double z = capture::depth(camera, p);
    zmin = std::min(zmin, z);
    zmax = std::max(zmax, z);
  }
  const double margin = 0.01 * (zmax - zmin) + 1.0;
  double n = zmin - margin, f = zmax + margin;
  if (camera.projection == capture::Projection::Perspective) {
    if (f <= 0) return {0.0, 0.0};
    n = std::max(n, std::max(1e-4 * f, 1e-3));
  }
  return {n, f};
}

std::array<float, 16> clip_from_head(const capture::CameraModel& c, double n, double f) {
  // clip from camera (OpenCV axes); window x = u, window y = v (image row, not flipped).
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  const double ax = 2 * c.fx / c.width, bx = 2 * c.cx / c.width - 1;
  const double ay = 2 * c.fy / c.height, by = 2 * c.cy / c.height - 1;
  if (c.projection == capture::Projection::Orthographic) {
    p << ax, 0, 0, bx, 0, ay, 0, by, 0, 0, 2 / (f - n), -(f + n) / (f - n), 0, 0, 0, 1;
  } else {
    p << ax, 0, bx, 0, 0, ay, by, 0, 0, 0, (f + n) / (f - n), -2 * f * n / (f - n), 0, 0, 1, 0;
  }
  const Eigen::Matrix4d m = p * c.cam_from_head.matrix();
  std::array<float, 16> out{};
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) out[col * 4 + row] = float(m(row, col));
  return out;
}

void window_depth_to_zcam(cv::Mat& depth, double n, double f, bool perspective, cv::Mat* mask) {
  if (mask) mask->create(depth.size(), CV_8U);
  const float inf = std::numeric_limits<float>::infinity(), fn = float(f * n), span = float(f - n),
              near = float(n), far = float(f);
  for (int r = 0; r < depth.rows; ++r) {
    float* z = depth.ptr<float>(r);
    std::uint8_t* drawn = mask ? mask->ptr<std::uint8_t>(r) : nullptr;
    for (int c = 0; c < depth.cols; ++c) {
      const float d = z[c];
      // perspective: the inverse of the clip z, z = f n / (f - d (f - n)); orthographic: linear
      z[c] = d >= 1.0f ? inf : perspective ? fn / (far - d * span) : near + d * span;
      if (drawn) drawn[c] = d < 1.0f ? 255 : 0;
    }
  }
}

std::array<float, 4> zcam_row(const capture::CameraModel& c) {
  const Eigen::Matrix4d m = c.cam_from_head.matrix();
  return {float(m(2, 0)), float(m(2, 1)), float(m(2, 2)), float(m(2, 3))};
}

cv::Mat fit_texture_limit(const cv::Mat& image) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (image.cols <= max_size && image.rows <= max_size) return image;
  cv::Mat out;
  const double s = double(max_size) / std::max(image.cols, image.rows);
  cv::resize(image, out, cv::Size(), s, s, cv::INTER_AREA);
  return out;
}

void linear_clamp_parameters() {
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T})
    glTexParameteri(GL_TEXTURE_2D, wrap, GL_CLAMP_TO_EDGE);
}

GLuint upload_texture(const cv::Mat& image, GLuint tex) {
  cv::Mat rgba;
  if (image.channels() == 4)
    cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA);
  else
    cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA);
  rgba = fit_texture_limit(rgba);
  if (!tex) glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.cols, rgba.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rgba.data);
  linear_clamp_parameters();
  return tex;
}

void GpuMesh::release() {
  if (tex) glDeleteTextures(1, &tex);
  if (ebo) glDeleteBuffers(1, &ebo);
  if (vbo) glDeleteBuffers(1, &vbo);
  if (vao) glDeleteVertexArrays(1, &vao);
  tex = ebo = vbo = vao = 0;
}

GpuMesh upload_mesh(const mesh::TriMesh& m, bool with_texture) {
  GpuMesh g;
  const bool textured = with_texture && !m.texture.empty() && !m.uvs.empty();
  g.mode = textured ? 2 : (!m.colors.empty() ? 1 : 0);
  const auto normals = vertex_normals(m);
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
  if (textured) g.tex = upload_texture(m.texture, 0);
  return g;
}

RenderResult read_result(int w, int h, const std::array<double, 2>& nf, bool perspective,
                         bool with_depth) {
  RenderResult r;
  cv::Mat bgra(h, w, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data);
  // One pass, on this thread (cvtColor would wake OpenCV's workers for every frame).
  r.image.create(h, w, CV_8UC3);
  if (!with_depth) {
    r.mask.create(h, w, CV_8U);
    cv::Mat outs[2] = {r.image, r.mask};
    const int from_to[8] = {0, 0, 1, 1, 2, 2, 3, 3};
    cv::mixChannels(&bgra, 1, outs, 2, from_to, 4);
    return r;
  }
  const int from_to[6] = {0, 0, 1, 1, 2, 2};
  cv::mixChannels(&bgra, 1, &r.image, 1, from_to, 3);
  r.depth_mm.create(h, w, CV_32F);
  glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, r.depth_mm.data);
  window_depth_to_zcam(r.depth_mm, nf[0], nf[1], perspective, &r.mask);
  return r;
}

std::vector<Eigen::Vector3d> vertex_normals(const mesh::TriMesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d fn = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    for (int k = 0; k < 3; ++k) n[t[k]] += fn;  // |fn| = 2 * area: area weighting
  }
  for (auto& v : n) {
    const double len = v.norm();
    if (len > 0) v /= len;
  }
  return n;
}

}  // namespace orthoface::render::gl
