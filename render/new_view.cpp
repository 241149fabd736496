#include "render/new_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "model/symmetry.h"
#include "render/equalize.h"
#include "render/floating_textures.h"
#include "render/gl_util.h"
#include "render/new_view_shaders.h"
#include "render/source_textures.h"
#include "render/triangle_classes.h"
#include "render/unseen_fill.h"

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
  if (photo.channels() == 1)
    cv::cvtColor(photo, bgr, cv::COLOR_GRAY2BGR);
  else
    bgr = photo;
  return bgr;
}

// Occlusion test of a view program (the VISIBILITY define of kViewFragment).
enum class Visibility { kNone = 0, kPerVertex = 1, kPerPixel = 2 };

// Width of the pick blend's feather in cos0 - cos1, which changes by sqrt(2) per radian of
// normal rotation near the 45-degree switch; a tiny band stands for feather 0 (a hard switch) as
// smoothstep needs edge0 < edge1.
double feather_band(const SynthesisOptions& o) {
  return std::max(std::sqrt(2.0) * o.feather_deg * M_PI / 180, 1e-6);
}

// Unit direction from the head toward camera `c` (its viewing direction reversed).
Eigen::Vector3d toward(const capture::CameraModel& c) { return -capture::view_direction(c); }

// How near the new view (toward `view`) is to a source's own viewpoint (toward `source`):
// cos(angle between them)^power, 1 at the camera. At 32: 0.33 at 15 deg, 0.01 at 30 deg; at 8:
// 0.76 at 15 deg, 0.32 at 30 deg, 0.06 at 45 deg.
double own_viewpoint(const Eigen::Vector3d& source, const Eigen::Vector3d& view, double power) {
  return std::pow(std::clamp(view.dot(source), 0.0, 1.0), power);
}

// What the View blend adds to cos0 - cos1 for the new view (0 for the other blends), the side
// photo seen from `side` (the side camera's direction, or its mirror image's). The front photo is
// the reference: while the view is nearer the front camera than the side camera it is preferred
// by view_gain x the difference of the two cosines (the angle penalty of Buehler et al. 2001).
// Past 45 deg the seed's rule decides (the better-facing photo: a side photo sampled at a grazing
// angle is smeared). Near each camera's own viewpoint camera_gain gives that camera's photo
// back.
double view_bias(const Eigen::Vector3d& front, const Eigen::Vector3d& side,
                 const Eigen::Vector3d& view, const SynthesisOptions& o) {
  if (o.blend != Blend::View) return 0;
  const double toward_front = view.dot(front) - view.dot(side);
  return o.view_gain * std::max(toward_front, 0.0) +
         o.camera_gain * (own_viewpoint(front, view, o.camera_power) -
                          own_viewpoint(side, view, o.camera_power));
}

// Facing cosine over which a source's share rises to 1 (a grazing sample is stretched). Under
// the View blend it narrows as the view nears that camera (by cos^ramp_narrowing of the angle
// between them), where the stretch goes away (at the camera a grazing sample is exactly the
// photo's pixel); never wider than 0.1, which triangle_facts' "whole" test assumes.
double facing_ramp(const Eigen::Vector3d& source, const Eigen::Vector3d& view,
                   const SynthesisOptions& o) {
  constexpr double kRamp = 0.1;
  if (o.blend != Blend::View) return kRamp;
  return std::max(kRamp * (1 - own_viewpoint(source, view, o.ramp_narrowing)), 1e-4);
}

// The synthesis fragment shader specialised for the rig's source cameras and the options.
std::string view_fragment(const capture::RigCalibration& rig, Visibility visibility, bool weighted,
                          int only_source, bool sources_out, bool mirror) {
  std::string defines = "#version 330 core\n";
  if (sources_out) defines += "#define SOURCES_OUT 1\n";
  if (mirror) defines += "#define MIRROR 1\n";
  defines += "#define VISIBILITY " + std::to_string(int(visibility)) + "\n";
  if (only_source >= 0) defines += "#define ONLY_SOURCE " + std::to_string(only_source) + "\n";
  if (weighted) defines += "#define WEIGHTED 1\n";
  const capture::CameraModel* cams[2] = {&rig.front, &rig.side};
  for (int i = 0; i < 2; ++i) {
    const bool perspective = cams[i]->projection == capture::Projection::Perspective;
    bool distorted = false;
    if (perspective)
      for (size_t k = 0; k < cams[i]->distortion.size() && k < 5; ++k)
        distorted = distorted || cams[i]->distortion[k] != 0;
    defines += "#define PERSPECTIVE" + std::to_string(i) + (perspective ? " 1\n" : " 0\n");
    defines += "#define DISTORTED" + std::to_string(i) + (distorted ? " 1\n" : " 0\n");
  }
  return defines + shaders::kViewFragment;
}

// What view_fragment takes from the rig: each source's projection and whether it is distorted
// (the programs made for one rig serve any rig with the same key).
std::array<bool, 4> program_key(const capture::RigCalibration& rig) {
  std::array<bool, 4> key{};
  const capture::CameraModel* cams[2] = {&rig.front, &rig.side};
  for (int i = 0; i < 2; ++i) {
    key[2 * i] = cams[i]->projection == capture::Projection::Perspective;
    if (key[2 * i])
      for (size_t k = 0; k < cams[i]->distortion.size() && k < 5; ++k)
        key[2 * i + 1] = key[2 * i + 1] || cams[i]->distortion[k] != 0;
  }
  return key;
}

}  // namespace

Blend parse_blend(const std::string& name) {
  if (name == "view") return Blend::View;
  if (name == "pick") return Blend::Pick;
  if (name == "weighted") return Blend::Weighted;
  throw std::invalid_argument("blend must be view, pick or weighted, got '" + name + "'");
}

const char* blend_name(Blend blend) {
  switch (blend) {
    case Blend::View:
      return "view";
    case Blend::Pick:
      return "pick";
    case Blend::Weighted:
      return "weighted";
  }
  return "?";
}

UnseenSide parse_unseen_side(const std::string& name) {
  if (name == "view") return UnseenSide::MirrorView;
  if (name == "texture") return UnseenSide::MirrorTexture;
  if (name == "front") return UnseenSide::Front;
  throw std::invalid_argument("unknown unseen-side source '" + name +
                              "' (expected view, texture or front)");
}

const char* unseen_side_name(UnseenSide unseen) {
  switch (unseen) {
    case UnseenSide::MirrorView:
      return "view";
    case UnseenSide::MirrorTexture:
      return "texture";
    case UnseenSide::Front:
      return "front";
  }
  return "?";
}

void SynthesisOptions::check() const {
  auto bad = [](const std::string& field) {
    throw std::invalid_argument("new view options: " + field);
  };
  if (!(feather_deg >= 0 && feather_deg <= 45)) bad("feather_deg must be in 0..45");
  if (!(weighted_power > 0 && weighted_power <= 16)) bad("weighted_power must be in (0, 16]");
  if (!(view_gain >= 0 && view_gain <= 10)) bad("view_gain must be in 0..10");
  if (!(camera_gain >= 0 && camera_gain <= 10)) bad("camera_gain must be in 0..10");
  if (!(camera_power >= 1 && camera_power <= 4096)) bad("camera_power must be in 1..4096");
  if (!(hull_view_share >= 0 && hull_view_share <= 1)) bad("hull_view_share must be in 0..1");
  if (!(mirror_view_from_deg >= 0 && mirror_view_from_deg <= 180))
    bad("mirror_view_from_deg must be in 0..180");
  if (!(visibility_tolerance_mm >= 0 && visibility_tolerance_mm <= 100))
    bad("visibility_tolerance_mm must be in 0..100");
  if (blend_bands < 1 || blend_bands > 12) bad("blend_bands must be in 1..12");
  if (!(ramp_narrowing >= 1 && ramp_narrowing <= 256)) bad("ramp_narrowing must be in 1..256");
  if (!(hull_max_stretch == 0 || (hull_max_stretch >= 1.5 && hull_max_stretch <= 100)))
    bad("hull_max_stretch must be 0 or in 1.5..100");
  if (body_camera && !capture::camera_problem(*body_camera).empty())
    bad("body_camera: " + capture::camera_problem(*body_camera));
  if (!body_pivot.allFinite()) bad("body_pivot must be finite");
}

struct ViewSynthesizer::Impl {
  gl::Context context;
  // By mirror, sources out, Visibility, weighted and only source; made on first use.
  GLuint view_prog[72] = {};
  GLuint depth_prog = 0, equalize_prog = 0;
  GLuint empty_vao = 0;  // the equalisation pass draws without vertex buffers
  gl::GpuMesh mesh;
  GLuint seen_vbo = 0;     // per-vertex visibility in each source, face or not (attribute 4)
  GLuint turn_vbo = 0;     // per-vertex turn weight (attribute 5; 1 when none is set)
  bool has_turn = false;   // set_turn_weights gave weights for this mesh
  int face_vertices = -1;  // set_face_vertices (-1: all)
  std::vector<Eigen::Vector3d> vertices, normals;
  std::vector<std::array<int, 3>> triangles;
  // The element buffer in TriangleClass order, `class_count` indices of each, for the options
  // in `ordered_for` (the blend and visibility settings; none: mesh order, all kTested).
  std::optional<SynthesisOptions> ordered_for;
  double ordered_bias = 0;  // the view bias the element buffer was sorted for
  std::array<GLsizei, 4> class_count{};
  std::vector<TriangleFacts> facts;  // per triangle (mesh order), made for `facts_for`
  std::optional<SynthesisOptions> facts_for;
  capture::RigCalibration rig;
  detail::SourceGl src[2];
  bool has_photos = false;
  ColourMatch match;
  gl::Framebuffer fb;

  Impl() {
    depth_prog =
        gl::program(shaders::kSourceDepthVertex, shaders::kSourceDepthFragment, "source_depth");
    equalize_prog = gl::program(shaders::kEqualizeVertex, shaders::kEqualizeFragment, "equalize");
    glUseProgram(equalize_prog);
    glUniform1i(glGetUniformLocation(equalize_prog, "photo"), 0);
    glUniform1i(glGetUniformLocation(equalize_prog, "lut"), 1);
    glUniform1f(glGetUniformLocation(equalize_prog, "lut_size"), float(detail::kLutSize));
    glGenVertexArrays(1, &empty_vao);
    glVertexAttrib1f(5, 1.0f);  // no turn weights: every vertex turns with the view
  }
  ~Impl() {
    context.make_current();
    for (auto& s : src) {
      const GLuint tex[4] = {s.zmap, s.photo, s.photo_eq, s.lut};
      glDeleteTextures(4, tex);
      if (s.eq_fbo) glDeleteFramebuffers(1, &s.eq_fbo);
      if (s.depth_fbo) glDeleteFramebuffers(1, &s.depth_fbo);
    }
    glDeleteVertexArrays(1, &empty_vao);
    if (seen_vbo) glDeleteBuffers(1, &seen_vbo);
    if (turn_vbo) glDeleteBuffers(1, &turn_vbo);
    mesh.release();
    fb.release();
    for (GLuint p : view_prog)
      if (p) glDeleteProgram(p);
    glDeleteProgram(depth_prog);
    glDeleteProgram(equalize_prog);
  }

  const capture::CameraModel& cam(int i) const { return i == 0 ? rig.front : rig.side; }
  void upload_seen();
  bool seen_stale = false;  // the sources' depth maps changed since upload_seen
  void sort_elements(const SynthesisOptions& o, double bias);
  void upload_photos(const cv::Mat& front, const cv::Mat& side);
  // New photos (checked): uploaded, the colour match recomputed when asked or first, equalised.
  void load_photos(const cv::Mat& front, const cv::Mat& side, ColourUpdate colour);
  // Photo masks (set_photo_masks): checked (throws before anything changes), then kept eroded.
  void check_masks(const cv::Mat& front, const cv::Mat& side) const;
  void store_masks(const cv::Mat& front, const cv::Mat& side);
  void match_colours();
  // photo_eq = lookup(photo) over each source's footprint; `keep` leaves the texels already
  // equalised with these photos and this match (`equalized`) as they are.
  void equalize_photos(bool keep = false);
  std::array<cv::Rect, 2> equalized{};  // photo_eq texels equalised (texture coordinates)
  void source_uniforms(GLuint prog);
  GLuint view_program(Visibility visibility, bool weighted, int only_source, bool sources_out,
                      bool mirror);
  std::optional<Eigen::Vector4d> mirror_plane;  // set_mirror_plane
};

// Per-vertex visibility in each source (the fast path's occlusion test) and whether the vertex
// is the face's (set_face_vertices), attribute 4.
void ViewSynthesizer::Impl::upload_seen() {
  const cv::Mat depth[2] = {detail::read_source_depth(src[0]), detail::read_source_depth(src[1])};
  std::vector<float> seen(vertices.size() * 3);
  for (size_t v = 0; v < vertices.size(); ++v) {
    for (int i = 0; i < 2; ++i) {
      const double cosine = detail::facing(cam(i), vertices[v], normals[v]);
      seen[3 * v + i] = detail::source_sees(cam(i), depth[i], vertices[v], cosine, 1.0);
    }
    seen[3 * v + 2] = face_vertices < 0 || v < size_t(face_vertices) ? 1.0f : 0.0f;
  }
  glBindVertexArray(mesh.vao);
  if (!seen_vbo) glGenBuffers(1, &seen_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, seen_vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(seen.size() * sizeof(float)), seen.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(4);
  glVertexAttribPointer(4, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glBindVertexArray(0);
  seen_stale = false;
}

// The element buffer sorted by TriangleClass for the view's bias (render/triangle_classes.h).
// What kViewFragment computes for a surface point depends on the view only through the view
// bias of the View blend (a constant per view): the facing cosines, the photo positions and the
// occlusion test against the sources' depth maps are all fixed by the mesh and the rig. So
// triangles where it is provably one photo alone, or where neither depth map occludes the
// triangle, are drawn by cheaper programs with the same result; the rest by the full one.
void ViewSynthesizer::Impl::sort_elements(const SynthesisOptions& o, double bias) {
  if (!facts_for || facts_for->visibility_tolerance_mm != o.visibility_tolerance_mm) {
    std::array<TriangleSource, 2> sources;
    for (int i = 0; i < 2; ++i)  // texture texels = photo pixels: the mask tests are exact
      sources[i] = {cam(i), detail::read_source_depth(src[i]), src[i].mask,
                    src[i].photo_size == src[i].raw.size()};
    facts = triangle_facts(vertices, normals, triangles, sources, o.visibility_tolerance_mm);
    facts_for = o;
    ordered_for.reset();
  }
  const bool weighted = o.blend == Blend::Weighted;
  if (ordered_for && (ordered_for->blend == Blend::Weighted) == weighted &&
      ordered_for->feather_deg == o.feather_deg &&
      ordered_for->hull_view_share == o.hull_view_share && ordered_bias == bias)
    return;
  const TriangleOrder order = order_triangles(
      triangles, facts, {weighted, feather_band(o), bias, o.hull_view_share, face_vertices});
  for (int k = 0; k < 4; ++k) class_count[k] = GLsizei(3 * order.count[k]);
  glBindVertexArray(mesh.vao);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.ebo);
  glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0,
                  GLsizeiptr(order.triangles.size() * sizeof(order.triangles[0])),
                  order.triangles.data());
  glBindVertexArray(0);
  ordered_for = o;
  ordered_bias = bias;
}

// Raw photo textures updated in place; a CPU copy is kept for the colour match.
void ViewSynthesizer::Impl::upload_photos(const cv::Mat& front, const cv::Mat& side) {
  front.copyTo(src[0].raw);
  side.copyTo(src[1].raw);
  for (detail::SourceGl& s : src) detail::upload_bgr(s.raw, s.mask, s.photo, s.photo_size);
  has_photos = true;
}

// Equalisation statistics from the current mesh, source depth maps and photos, as one lookup
// texture per source.
void ViewSynthesizer::Impl::match_colours() {
  match =
      detail::colour_match(vertices, normals, rig,
                           {detail::read_source_depth(src[0]), detail::read_source_depth(src[1])},
                           {src[0].raw, src[1].raw});
  for (int i = 0; i < 2; ++i)
    detail::upload_lut(detail::equalize_grid(match, i, detail::kLutSize), src[i].lut);
}

// photo_eq = lookup(photo), one full-frame pass per source on the GL side (no CPU colour work).
void ViewSynthesizer::Impl::equalize_photos(bool keep) {
  glUseProgram(equalize_prog);
  glEnable(GL_SCISSOR_TEST);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glBindVertexArray(empty_vao);
  for (detail::SourceGl& s : src) {
    // The front photo is the reference: the views sample its raw texture (render_direct).
    if (&s == &src[0]) continue;
    detail::ensure_target(s.photo_eq, s.photo_eq_size, s.eq_fbo, s.photo_size);
    glBindFramebuffer(GL_FRAMEBUFFER, s.eq_fbo);
    glDrawBuffer(GL_COLOR_ATTACHMENT0);
    glViewport(0, 0, s.photo_size.width, s.photo_size.height);
    const double to_texture = double(s.photo_size.width) / s.raw.cols;  // 1 unless downscaled
    const cv::Rect f(cv::Point(int(std::floor(s.footprint.x * to_texture)),
                               int(std::floor(s.footprint.y * to_texture))),
                     cv::Point(int(std::ceil(s.footprint.br().x * to_texture)),
                               int(std::ceil(s.footprint.br().y * to_texture))));
    // With `keep`, only the strips of f outside the texels already equalised.
    const int i = int(&s - src);
    const cv::Rect e = keep ? equalized[i] & f : cv::Rect();
    std::array<cv::Rect, 4> parts{f};
    if (!e.empty())
      parts = {cv::Rect(f.x, f.y, f.width, e.y - f.y),
               cv::Rect(f.x, e.br().y, f.width, f.br().y - e.br().y),
               cv::Rect(f.x, e.y, e.x - f.x, e.height),
               cv::Rect(e.br().x, e.y, f.br().x - e.br().x, e.height)};
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, s.photo);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, s.lut);
    for (const cv::Rect& part : parts) {
      if (part.empty()) continue;
      glScissor(part.x, part.y, part.width, part.height);  // GL window row = image row
      glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    equalized[i] = f;
  }
  glDisable(GL_SCISSOR_TEST);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

GLuint ViewSynthesizer::Impl::view_program(Visibility visibility, bool weighted, int only_source,
                                           bool sources_out, bool mirror) {
  GLuint& p = view_prog[36 * int(mirror) + 18 * int(sources_out) + 6 * (only_source + 1) +
                        2 * int(visibility) + int(weighted)];
  if (!p) {
    const std::string vertex = std::string("#version 330 core\n") +
                               (mirror ? "#define MIRROR 1\n" : "") + shaders::kViewVertex;
    p = gl::program(
        vertex.c_str(),
        view_fragment(rig, visibility, weighted, only_source, sources_out, mirror).c_str(),
        "new_view");
    source_uniforms(p);
  }
  return p;
}

namespace {

// What the view shader's facing() needs of camera `index` (0 front, 1 side, 2 the new view):
// its projection, centre and direction (head frame).
void facing_uniforms(GLuint prog, int index, const capture::CameraModel& c) {
  const std::string at = "[" + std::to_string(index) + "]";
  auto loc = [&](const std::string& name) {
    return glGetUniformLocation(prog, (name + at).c_str());
  };
  glUniform1i(loc("persp"), c.projection == capture::Projection::Perspective ? 1 : 0);
  const Eigen::Vector3f centre = c.cam_from_head.inverse().translation().cast<float>();
  const Eigen::Vector3f toward = (-capture::view_direction(c)).cast<float>();
  glUniform3f(loc("centre"), centre.x(), centre.y(), centre.z());
  glUniform3f(loc("toward"), toward.x(), toward.y(), toward.z());
}

}  // namespace

// Uniforms that depend only on the rig and the source depth maps.
void ViewSynthesizer::Impl::source_uniforms(GLuint prog) {
  glUseProgram(prog);
  auto loc = [&](const std::string& name) { return glGetUniformLocation(prog, name.c_str()); };
  for (int i = 0; i < 2; ++i) {
    const capture::CameraModel& c = cam(i);
    const std::string at = i == 0 ? "[0]" : "[1]";
    const Eigen::Matrix4f m = c.cam_from_head.matrix().cast<float>();
    glUniformMatrix4fv(loc("src_from_head" + at), 1, GL_FALSE, m.data());
    glUniform4f(loc("intr" + at), float(c.fx), float(c.fy), float(c.cx), float(c.cy));
    glUniform2f(loc("size" + at), float(c.width), float(c.height));
    double k[5] = {0, 0, 0, 0, 0};
    if (c.projection == capture::Projection::Perspective)
      for (size_t j = 0; j < c.distortion.size() && j < 5; ++j) k[j] = c.distortion[j];
    glUniform4f(loc("dist" + at), float(k[0]), float(k[1]), float(k[2]), float(k[3]));
    glUniform1f(loc("k3" + at), float(k[4]));
    facing_uniforms(prog, i, c);
    glUniform2f(loc("zrange" + at), float(src[i].zrange[0]), float(src[i].zrange[1]));
  }
  const char* samplers[4] = {"photo0", "photo1", "zmap0", "zmap1"};
  for (int t = 0; t < 4; ++t) glUniform1i(loc(samplers[t]), t);
}

ViewSynthesizer::ViewSynthesizer(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                                 const cv::Mat& front, const cv::Mat& side) {
  gl::check_camera(rig.front, "new view: front camera");
  gl::check_camera(rig.side, "new view: side camera");
  as_bgr(front, rig.front, "front");
  as_bgr(side, rig.side, "side");
  mesh::check_mesh(mesh, "new view: mesh");
  impl_ = std::make_unique<Impl>();
  impl_->rig = rig;
  set_mesh(mesh);
  set_photos(front, side);
}

ViewSynthesizer::~ViewSynthesizer() = default;

void ViewSynthesizer::set_mesh(const mesh::TriMesh& mesh) {
  mesh::check_mesh(mesh, "new view: mesh");
  impl_->context.make_current();
  impl_->mesh.release();
  impl_->mesh = gl::upload_mesh(mesh, false);
  impl_->vertices = mesh.vertices;
  impl_->face_vertices = -1;
  impl_->has_turn = false;  // a new vertex array: attribute 5 is off, every vertex turns
  impl_->triangles.assign(mesh.triangles.begin(), mesh.triangles.end());
  impl_->ordered_for.reset();  // mesh order
  impl_->facts_for.reset();
  impl_->normals = gl::vertex_normals(mesh);
  for (int i = 0; i < 2; ++i) {
    impl_->src[i].footprint = detail::photo_footprint(impl_->cam(i), impl_->vertices);
    detail::render_source_depth(impl_->cam(i), impl_->mesh, impl_->depth_prog, impl_->src[i]);
  }
  impl_->upload_seen();
  for (GLuint p : impl_->view_prog)
    if (p) impl_->source_uniforms(p);
  if (impl_->has_photos) update_colour_match();  // the surface both cameras see has changed
}

void ViewSynthesizer::set_rig(const capture::RigCalibration& rig) {
  gl::check_camera(rig.front, "new view: front camera");
  gl::check_camera(rig.side, "new view: side camera");
  Impl& m = *impl_;
  as_bgr(m.src[0].raw, rig.front, "front");  // the photos stay: their cameras keep their sizes
  as_bgr(m.src[1].raw, rig.side, "side");
  m.context.make_current();
  if (program_key(rig) != program_key(m.rig))  // the shaders are specialised for the cameras
    for (GLuint& p : m.view_prog) {
      if (p) glDeleteProgram(p);
      p = 0;
    }
  m.rig = rig;
  m.ordered_for.reset();  // triangle classes: facing, photo positions and occlusion per source
  m.facts_for.reset();
  for (int i = 0; i < 2; ++i) {
    m.src[i].footprint = detail::photo_footprint(m.cam(i), m.vertices);
    detail::render_source_depth(m.cam(i), m.mesh, m.depth_prog, m.src[i]);
  }
  // The per-vertex visibility (only the per-vertex programs read it) is made again by the next
  // render that needs it: per-pixel renders use the depth maps on the GL side alone.
  m.seen_stale = true;
  for (GLuint p : m.view_prog)
    if (p) m.source_uniforms(p);
  // The colour match is kept: the photos are equalised again only where the new footprints
  // reach past the texels already equalised.
  m.equalize_photos(true);
}

void ViewSynthesizer::set_face_vertices(int count) {
  if (count < -1 || count > int(impl_->vertices.size()))
    throw std::invalid_argument("set_face_vertices: " + std::to_string(count) +
                                " is not -1 or a vertex count of 0.." +
                                std::to_string(impl_->vertices.size()));
  impl_->context.make_current();
  impl_->face_vertices = count;
  impl_->ordered_for.reset();  // the hull's triangles are classed by the hull's bias
  impl_->upload_seen();
}

void ViewSynthesizer::set_turn_weights(const std::vector<float>& weights) {
  Impl& m = *impl_;
  if (!weights.empty() && weights.size() != m.vertices.size())
    throw std::invalid_argument("set_turn_weights: " + std::to_string(weights.size()) +
                                " weights for " + std::to_string(m.vertices.size()) + " vertices");
  for (float w : weights)
    if (!(w >= 0 && w <= 1))
      throw std::invalid_argument("set_turn_weights: a weight is outside 0..1");
  m.context.make_current();
  glBindVertexArray(m.mesh.vao);
  if (weights.empty()) {
    glDisableVertexAttribArray(5);
  } else {
    if (!m.turn_vbo) glGenBuffers(1, &m.turn_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m.turn_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(weights.size() * sizeof(float)), weights.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(5);
    glVertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  glBindVertexArray(0);
  m.has_turn = !weights.empty();
}

void ViewSynthesizer::set_photos(const cv::Mat& front, const cv::Mat& side, ColourUpdate colour) {
  const cv::Mat f = as_bgr(front, impl_->rig.front, "front");
  const cv::Mat s = as_bgr(side, impl_->rig.side, "side");
  impl_->load_photos(f, s, colour);
}

void ViewSynthesizer::set_photo_masks(const cv::Mat& front, const cv::Mat& side) {
  impl_->check_masks(front, side);
  impl_->store_masks(front, side);
  impl_->context.make_current();
  impl_->upload_photos(impl_->src[0].raw.clone(), impl_->src[1].raw.clone());
  impl_->equalize_photos();
}

void ViewSynthesizer::set_photos(const cv::Mat& front, const cv::Mat& side,
                                 const cv::Mat& front_mask, const cv::Mat& side_mask,
                                 ColourUpdate colour) {
  const cv::Mat f = as_bgr(front, impl_->rig.front, "front");
  const cv::Mat s = as_bgr(side, impl_->rig.side, "side");
  impl_->check_masks(front_mask, side_mask);
  impl_->store_masks(front_mask, side_mask);
  impl_->load_photos(f, s, colour);
}

void ViewSynthesizer::Impl::load_photos(const cv::Mat& front, const cv::Mat& side,
                                        ColourUpdate colour) {
  const bool first = !has_photos;
  context.make_current();
  upload_photos(front, side);
  if (first || colour == ColourUpdate::Recompute) match_colours();
  equalize_photos();
}

void ViewSynthesizer::Impl::check_masks(const cv::Mat& front, const cv::Mat& side) const {
  const cv::Mat masks[2] = {front, side};
  for (int i = 0; i < 2; ++i) {
    const capture::CameraModel& c = cam(i);
    if (!masks[i].empty() &&
        (masks[i].type() != CV_8UC1 || masks[i].cols != c.width || masks[i].rows != c.height))
      throw std::invalid_argument(std::string("new view: ") + (i ? "side" : "front") +
                                  " photo mask must be CV_8U of the camera's size " +
                                  std::to_string(c.width) + "x" + std::to_string(c.height));
  }
}

void ViewSynthesizer::Impl::store_masks(const cv::Mat& front, const cv::Mat& side) {
  const cv::Mat masks[2] = {front, side};
  for (int i = 0; i < 2; ++i) {
    if (masks[i].empty()) {
      src[i].mask.release();
      continue;
    }
    cv::erode(masks[i] != 0, src[i].mask, cv::Mat());  // 3x3: one pixel
  }
  ordered_for.reset();  // the masks decide which triangles take one photo alone
  facts_for.reset();
}

void ViewSynthesizer::set_mirror_plane(const std::optional<Eigen::Vector4d>& plane) {
  if (plane) model::reflection(*plane);  // checks the plane
  impl_->mirror_plane = plane;
}

const std::optional<Eigen::Vector4d>& ViewSynthesizer::mirror_plane() const {
  return impl_->mirror_plane;
}

void ViewSynthesizer::update_colour_match() {
  impl_->context.make_current();
  impl_->match_colours();
  impl_->equalize_photos();
}

const ColourMatch& ViewSynthesizer::colour_match() const { return impl_->match; }

cv::Mat ViewSynthesizer::source_depth(int source) const {
  if (source != 0 && source != 1)
    throw std::invalid_argument("new view: source must be 0 (front) or 1 (side), got " +
                                std::to_string(source));
  impl_->context.make_current();
  return detail::read_source_depth(impl_->src[source]).clone();
}

bool ViewSynthesizer::mirrors_view(const capture::CameraModel& camera,
                                   const SynthesisOptions& o) const {
  const Impl& m = *impl_;
  if (o.unseen != UnseenSide::MirrorView || !m.mirror_plane) return false;
  const Eigen::Vector3d n = m.mirror_plane->head<3>();
  const Eigen::Vector3d to_view = toward(camera), to_side = toward(m.rig.side);
  const double angle_deg =
      std::acos(std::clamp(to_view.dot(toward(m.rig.front)), -1.0, 1.0)) * 180 / M_PI;
  return to_view.dot(n) * to_side.dot(n) < 0 && angle_deg >= o.mirror_view_from_deg;
}

SynthesisResult ViewSynthesizer::render(const capture::CameraModel& camera,
                                        const SynthesisOptions& o) {
  o.check();
  gl::check_camera(camera, "new view: camera");
  if (!mirrors_view(camera, o)) return render_direct(camera, o);
  // The mirror image's view stands on the photographed side; flipped, it is this view of the
  // mirrored head.
  SynthesisOptions mo = o;
  if (o.body_camera) {
    const Eigen::Vector4d& plane = *impl_->mirror_plane;
    mo.body_camera = capture::reflected(*o.body_camera, plane);
    const Eigen::Vector3d n = plane.head<3>();
    mo.body_pivot = o.body_pivot - 2 * (n.dot(o.body_pivot) - plane[3]) * n;
  }
  // The body, which does not turn, keeps the front photo's own picture: drawn through the
  // reflected camera and flipped, each of its points reads the colour of its mirror image.
  Eigen::Matrix4f body_from_head = Eigen::Matrix4f::Identity();
  if (o.body_camera) body_from_head = model::reflection(*impl_->mirror_plane).cast<float>();
  SynthesisResult r =
      render_direct(capture::reflected(camera, *impl_->mirror_plane), mo, body_from_head);
  for (cv::Mat* image : {&r.view.image, &r.view.mask, &r.view.depth_mm, &r.weights})
    if (!image->empty()) cv::flip(*image, *image, 1);
  return r;
}

SynthesisResult ViewSynthesizer::render_direct(const capture::CameraModel& camera,
                                               const SynthesisOptions& o,
                                               const Eigen::Matrix4f& body_from_head) {
  Impl& m = *impl_;
  m.context.make_current();
  if (!o.per_pixel_visibility && m.seen_stale) m.upload_seen();  // after set_rig
  // Attachments: the blend, the source weights, and for floating textures each photo alone.
  const bool floating = o.float_textures;
  const int outputs = floating ? 4 : o.source_weights || o.fill_unseen ? 2 : 1;
  m.fb.ensure(camera.width, camera.height, {GL_RGBA8, GL_RGBA8, GL_RGBA8, GL_RGBA8});
  const GLenum bufs[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                          GL_COLOR_ATTACHMENT3};
  glDrawBuffers(4, bufs);
  glViewport(0, 0, camera.width, camera.height);
  // Alpha 0 on the background, 1 where the mesh is drawn: the mask without a depth readback.
  const float bg[4] = {float(o.background[2] / 255), float(o.background[1] / 255),
                       float(o.background[0] / 255), 0.0f};
  const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
  glClearBufferfv(GL_COLOR, 0, bg);
  for (int b = 1; b < outputs; ++b) glClearBufferfv(GL_COLOR, b, zero);
  glClearBufferfv(GL_DEPTH, 0, &one);
  glDrawBuffers(outputs, bufs);
  const auto nf = gl::near_far(camera, m.mesh.lo, m.mesh.hi);
  // Floating textures need both photos' colours everywhere, and the mirror image colours
  // triangles the side photo cannot see: every triangle takes the blend program (no one-photo
  // or untested classes).
  const bool mirror = m.mirror_plane.has_value() && o.unseen == UnseenSide::MirrorTexture;
  const bool sorted = o.per_pixel_visibility && o.skip_unoccluded && !floating && !mirror;
  const Eigen::Matrix4d reflect =
      mirror ? model::reflection(*m.mirror_plane) : Eigen::Matrix4d::Identity();
  const Eigen::Vector3d to_view = toward(camera), to_front = toward(m.rig.front),
                        to_side = toward(m.rig.side),
                        to_mirror = (reflect.topLeftCorner<3, 3>() * to_side).normalized();
  if (nf[1] > nf[0]) {
    const auto clip = gl::clip_from_head(camera, nf[0], nf[1]);
    const bool weighted = o.blend == Blend::Weighted;
    const double feather = feather_band(o);
    const double bias = view_bias(to_front, to_side, to_view, o);
    const Eigen::Matrix4f reflect_f = reflect.cast<float>();
    // The body's turn back (SynthesisOptions::body_camera): the rotation taking a point to where
    // this camera sees it as the body camera sees the point itself.
    Eigen::AngleAxisd twist(0, Eigen::Vector3d::UnitY());
    if (o.body_camera && m.has_turn)
      twist = Eigen::AngleAxisd(
          (camera.cam_from_head.inverse() * o.body_camera->cam_from_head).linear());
    auto draw = [&](Visibility visibility, int only_source, GLsizei first, GLsizei count) {
      if (count == 0) return;
      const GLuint p = m.view_program(visibility, weighted, only_source, floating, mirror);
      glUseProgram(p);
      glUniformMatrix4fv(glGetUniformLocation(p, "clip_from_head"), 1, GL_FALSE, clip.data());
      glUniformMatrix4fv(glGetUniformLocation(p, "mirror"), 1, GL_FALSE, reflect_f.data());
      glUniform4f(glGetUniformLocation(p, "twist"), float(twist.axis().x()),
                  float(twist.axis().y()), float(twist.axis().z()), float(twist.angle()));
      glUniform3f(glGetUniformLocation(p, "twist_pivot"), float(o.body_pivot.x()),
                  float(o.body_pivot.y()), float(o.body_pivot.z()));
      glUniformMatrix4fv(glGetUniformLocation(p, "body_from_head"), 1, GL_FALSE,
                         body_from_head.data());
      glUniform1f(glGetUniformLocation(p, "body_side"), body_from_head.isIdentity() ? 1.0f : 0.0f);
      glUniform1f(glGetUniformLocation(p, "feather"), float(feather));
      glUniform1f(glGetUniformLocation(p, "view_bias"), float(bias));
      glUniform1f(glGetUniformLocation(p, "hull_bias"), float(o.hull_view_share));
      glUniform1f(glGetUniformLocation(p, "view_bias_mirror"),
                  float(view_bias(to_front, to_mirror, to_view, o)));
      const float ramp[2] = {float(facing_ramp(to_front, to_view, o)),
                             float(facing_ramp(to_side, to_view, o))};
      glUniform1fv(glGetUniformLocation(p, "ramp"), 2, ramp);
      glUniform1f(glGetUniformLocation(p, "ramp_mirror"),
                  float(facing_ramp(to_mirror, to_view, o)));
      glUniform1f(glGetUniformLocation(p, "power"), float(o.weighted_power));
      facing_uniforms(p, 2, camera);
      const double s = o.hull_max_stretch;
      glUniform2f(glGetUniformLocation(p, "stretch"), s > 0 ? float(1 / s) : -2.0f,
                  s > 0 ? float(1 / (0.6 * s)) : -1.0f);
      glUniform1f(glGetUniformLocation(p, "tol_mm"), float(o.visibility_tolerance_mm));
      glUniform3f(glGetUniformLocation(p, "fill"), m.match.fill[2] / 255.0f,
                  m.match.fill[1] / 255.0f, m.match.fill[0] / 255.0f);
      glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(first * sizeof(GLuint)));
    };
    // The front photo is the equalisation's reference (unchanged): its raw texture.
    const GLuint tex[4] = {m.src[0].photo, o.equalize ? m.src[1].photo_eq : m.src[1].photo,
                           m.src[0].zmap, m.src[1].zmap};
    for (int t = 0; t < 4; ++t) {
      glActiveTexture(GLenum(GL_TEXTURE0 + t));
      glBindTexture(GL_TEXTURE_2D, tex[t]);
    }
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CW);  // window y = image row (see gl::clip_from_head)
    glEnable(GL_CULL_FACE);
    if (sorted) m.sort_elements(o, bias);
    glBindVertexArray(m.mesh.vao);
    if (!o.per_pixel_visibility) {
      draw(Visibility::kPerVertex, -1, 0, m.mesh.count);
    } else if (!sorted) {
      draw(Visibility::kPerPixel, -1, 0, m.mesh.count);
    } else {
      const auto& n = m.class_count;
      draw(Visibility::kNone, 0, 0, n[0]);
      draw(Visibility::kNone, 1, n[0], n[1]);
      draw(Visibility::kNone, -1, n[0] + n[1], n[2]);
      draw(Visibility::kPerPixel, -1, n[0] + n[1] + n[2], n[3]);
    }
    glBindVertexArray(0);
  }
  SynthesisResult r;
  if (sorted && nf[1] > nf[0]) {
    const auto& n = m.class_count;
    r.triangles_one_photo = int(n[0] + n[1]) / 3, r.triangles_untested = int(n[2]) / 3;
  }
  r.view = gl::read_result(camera.width, camera.height, nf,
                           camera.projection == capture::Projection::Perspective, o.depth);
  // Read on this thread, without cvtColor (see gl::read_result).
  auto read = [&](int attachment, GLenum format, int type) {
    cv::Mat m(camera.height, camera.width, type);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GLenum(GL_COLOR_ATTACHMENT0 + attachment));
    glReadPixels(0, 0, camera.width, camera.height, format, GL_UNSIGNED_BYTE, m.data);
    return m;
  };
  cv::Mat face;  // floating textures: where the face is drawn (weights' alpha)
  if (floating) {
    const cv::Mat rgba = read(1, GL_RGBA, CV_8UC4);  // (front, side, unseen, face)
    r.weights.create(rgba.size(), CV_8UC3);
    face.create(rgba.size(), CV_8U);
    cv::Mat outs[2] = {r.weights, face};
    const int from_to[8] = {0, 0, 1, 1, 2, 2, 3, 3};
    cv::mixChannels(&rgba, 1, outs, 2, from_to, 4);
  } else if (o.source_weights || o.fill_unseen) {
    r.weights = read(1, GL_RGB, CV_8UC3);  // (front, side, unseen)
  }
  if (floating && nf[1] > nf[0]) {
    FloatInputs in;
    for (int i = 0; i < 2; ++i) {
      const cv::Mat bgra = read(2 + i, GL_BGRA, CV_8UC4);
      in.source[i].create(bgra.size(), CV_8UC3);
      in.available[i].create(bgra.size(), CV_8U);
      cv::Mat outs[2] = {in.source[i], in.available[i]};
      const int from_to[8] = {0, 0, 1, 1, 2, 2, 3, 3};
      cv::mixChannels(&bgra, 1, outs, 2, from_to, 4);
    }
    // Only the face is aligned: elsewhere (the head hull's hair and neck) both photos count as
    // not seeing it, so no flow is found or applied there and the blend stays as drawn.
    const cv::Mat is_face = face > 127;
    for (cv::Mat& a : in.available) a &= is_face;
    in.weights = r.weights;
    in.mask = r.view.mask & is_face;
    in.fill = m.match.fill;
    auto cv3 = [](const Eigen::Vector3d& d) { return cv::Vec3d(d.x(), d.y(), d.z()); };
    in.alpha = float_alpha(cv3(to_view), cv3(to_front), cv3(to_side));
    if (mirror)  // the side never photographed: its reference is the mirror image's viewpoint
      in.alpha = std::max(in.alpha, float_alpha(cv3(to_view), cv3(to_front), cv3(to_mirror)));
    in.bands = o.blend_bands;
    in.round_trip = o.float_round_trip;
    r.view.image = float_textures(in, r.view.image).image;
  }
  if (o.fill_unseen && nf[1] > nf[0]) {
    cv::Mat unseen;
    cv::extractChannel(r.weights, unseen, 2);
    fill_unseen(r.view.image, unseen, r.view.mask, m.match.fill);
  }
  if (!o.source_weights) r.weights.release();
  return r;
}

SynthesisResult synthesize_view(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                                const cv::Mat& front, const cv::Mat& side,
                                const capture::CameraModel& camera,
                                const SynthesisOptions& options) {
  options.check();
  gl::check_camera(camera, "new view: camera");
  ViewSynthesizer synthesizer(mesh, rig, front, side);
  return synthesizer.render(camera, options);
}

}  // namespace orthoface::render
