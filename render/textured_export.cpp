#include "render/textured_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/equalize.h"
#include "render/gl_util.h"
#include "render/renderer.h"

namespace orthoface::render {
namespace {

// Photos (equalised if asked), source depth maps and normals shared by both exports.
struct Prepared {
  std::array<const capture::CameraModel*, 2> cams{};
  std::array<cv::Mat, 2> photos, depth;
  std::vector<Eigen::Vector3d> normals;
  ColourMatch match;
};

cv::Mat checked_photo(const cv::Mat& photo, const capture::CameraModel& cam,
                      const std::string& what) {
  if (photo.empty() || photo.depth() != CV_8U || (photo.channels() != 3 && photo.channels() != 1))
    throw std::invalid_argument("texture export: " + what + " photo must be 8-bit BGR or grey");
  if (photo.cols != cam.width || photo.rows != cam.height)
    throw std::invalid_argument("texture export: " + what + " photo size differs from its camera");
  cv::Mat bgr;
  if (photo.channels() == 1)
    cv::cvtColor(photo, bgr, cv::COLOR_GRAY2BGR);
  else
    bgr = photo;
  return bgr;
}

Prepared prepare(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                 const cv::Mat& front, const cv::Mat& side, const InheritOptions& o) {
  o.check();
  mesh::check_mesh(mesh, "texture export: mesh");
  gl::check_camera(rig.front, "texture export: front camera");
  gl::check_camera(rig.side, "texture export: side camera");
  Prepared p;
  p.cams = {&rig.front, &rig.side};
  const std::array<cv::Mat, 2> raw = {checked_photo(front, rig.front, "front"),
                                      checked_photo(side, rig.side, "side")};
  mesh::TriMesh bare;
  bare.vertices = mesh.vertices;
  bare.triangles = mesh.triangles;
  Renderer renderer;
  for (int i = 0; i < 2; ++i) p.depth[i] = renderer.render(bare, *p.cams[i]).depth_mm;
  p.normals = gl::vertex_normals(mesh);
  p.match = detail::colour_match(mesh.vertices, p.normals, rig, p.depth, raw);
  for (int i = 0; i < 2; ++i)
    p.photos[i] = o.equalize ? detail::equalized(raw[i], p.match, i) : raw[i];
  return p;
}

// Seed 004 §6 per triangle: the photo that sees all three vertices and that the face turns to.
int triangle_source(const Prepared& p, const mesh::TriMesh& m, const std::array<int, 3>& t) {
  const Eigen::Vector3d& a = m.vertices[t[0]];
  const Eigen::Vector3d& b = m.vertices[t[1]];
  const Eigen::Vector3d& c = m.vertices[t[2]];
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d centre = (a + b + c) / 3;
  int best = -1;
  double best_cos = 0;
  for (int i = 0; i < 2; ++i) {
    const double cosine = detail::facing(*p.cams[i], centre, n);
    if (!(cosine > best_cos)) continue;
    bool seen = true;
    for (int k = 0; k < 3 && seen; ++k)
      seen = detail::source_sees(*p.cams[i], p.depth[i], m.vertices[t[k]], cosine, 1.0);
    if (seen) best = i, best_cos = cosine;
  }
  return best;
}

}  // namespace

void InheritOptions::check() const {
  if (padding_px < 0 || padding_px > 64)
    throw std::invalid_argument("texture export options: padding_px must be in 0..64");
  if (max_atlas_px < 64 || max_atlas_px > 16384)
    throw std::invalid_argument("texture export options: max_atlas_px must be in 64..16384");
}

InheritedMesh inherit_texture(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                              const cv::Mat& front, const cv::Mat& side, const InheritOptions& o) {
  const Prepared p = prepare(mesh, rig, front, side, o);
  InheritedMesh out;
  out.source.resize(mesh.triangles.size());
  std::array<Eigen::Vector2d, 2> lo, hi;  // pixel bounding box of each photo's triangles
  std::array<bool, 2> used{false, false};
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const int s = out.source[t] = triangle_source(p, mesh, mesh.triangles[t]);
    if (s < 0) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d uv = capture::project(*p.cams[s], mesh.vertices[mesh.triangles[t][k]]);
      lo[s] = used[s] ? lo[s].cwiseMin(uv) : uv;
      hi[s] = used[s] ? hi[s].cwiseMax(uv) : uv;
      used[s] = true;
    }
  }
  // Atlas: [front region | side region | fill patch], each region padded and clipped.
  const int pad = o.padding_px, patch = 8;
  std::array<cv::Rect, 2> crop;
  int width = patch, height = patch;
  for (int i = 0; i < 2; ++i) {
    if (!used[i]) continue;
    const cv::Rect r(
        cv::Point(int(std::floor(lo[i].x())) - pad, int(std::floor(lo[i].y())) - pad),
        cv::Point(int(std::ceil(hi[i].x())) + pad + 1, int(std::ceil(hi[i].y())) + pad + 1));
    crop[i] = r & cv::Rect(0, 0, p.photos[i].cols, p.photos[i].rows);
    width += crop[i].width;
    height = std::max(height, crop[i].height);
  }
  cv::Mat atlas(height, width, CV_8UC3, cv::Scalar(p.match.fill));
  std::array<int, 2> x0{0, 0};
  int x = 0;
  for (int i = 0; i < 2; ++i) {
    x0[i] = x;
    if (!used[i]) continue;
    p.photos[i](crop[i]).copyTo(atlas(cv::Rect(x, 0, crop[i].width, crop[i].height)));
    x += crop[i].width;
  }
  const Eigen::Vector2d fill_uv((x + patch / 2.0) / width, 1.0 - (patch / 2.0) / height);
  // Each vertex keeps its index for the first photo (or fill) that uses it; where triangles of
  // another source meet it, a copy is appended (index = 3 * vertex + (source + 1)), so welding
  // the copies gives back the input mesh in its own vertex order.
  auto uv_of = [&](int v, int s) -> Eigen::Vector2d {
    if (s < 0) return fill_uv;
    const Eigen::Vector2d px = capture::project(*p.cams[s], mesh.vertices[v]);
    return {(px.x() - crop[s].x + x0[s]) / width, 1.0 - (px.y() - crop[s].y) / height};
  };
  constexpr int kUnused = -2;
  std::vector<int> primary(mesh.vertices.size(), kUnused);  // source of the vertex's own index
  std::vector<int> index(mesh.vertices.size() * 3, -1);
  mesh::TriMesh& m = out.mesh;
  m.vertices = mesh.vertices;
  m.uvs.assign(mesh.vertices.size(), fill_uv);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const int s = out.source[t];
    std::array<int, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      if (primary[v] == kUnused) {
        primary[v] = s;
        m.uvs[v] = uv_of(v, s);
      }
      int& id = index[3 * v + s + 1];
      if (id < 0) {
        if (primary[v] == s) {
          id = v;
        } else {
          id = int(m.vertices.size());
          m.vertices.push_back(mesh.vertices[v]);
          m.uvs.push_back(uv_of(v, s));
        }
      }
      tri[k] = id;
    }
    m.triangles.push_back(tri);
  }
  if (std::max(width, height) > o.max_atlas_px) {  // uvs are relative: only the image shrinks
    const double scale = double(o.max_atlas_px) / std::max(width, height);
    cv::resize(atlas, atlas, cv::Size(), scale, scale, cv::INTER_AREA);
  }
  m.texture = atlas;
  return out;
}

mesh::TriMesh inherit_vertex_colours(const mesh::TriMesh& mesh, const capture::RigCalibration& rig,
                                     const cv::Mat& front, const cv::Mat& side,
                                     const InheritOptions& o) {
  const Prepared p = prepare(mesh, rig, front, side, o);
  mesh::TriMesh m;
  m.vertices = mesh.vertices;
  m.triangles = mesh.triangles;
  const cv::Vec3d fill(p.match.fill[0], p.match.fill[1], p.match.fill[2]);
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    double cosine[2], seen[2];
    cv::Vec3d colour[2];
    for (int i = 0; i < 2; ++i) {
      cosine[i] = detail::facing(*p.cams[i], mesh.vertices[v], p.normals[v]);
      seen[i] = detail::source_sees(*p.cams[i], p.depth[i], mesh.vertices[v], cosine[i], 1.0);
      colour[i] = detail::bilinear(p.photos[i], capture::project(*p.cams[i], mesh.vertices[v]));
    }
    const double pf = cosine[0] >= cosine[1] ? 1.0 : 0.0;  // pick (seed 004 §6)
    const double w0 = seen[0] * (1 - seen[1]) + seen[0] * seen[1] * pf;
    const double w1 = seen[1] * (1 - seen[0]) + seen[0] * seen[1] * (1 - pf);
    const cv::Vec3d bgr = w0 * colour[0] + w1 * colour[1] + (1 - seen[0]) * (1 - seen[1]) * fill;
    m.colors.emplace_back(bgr[2] / 255, bgr[1] / 255, bgr[0] / 255);
  }
  return m;
}

}  // namespace orthoface::render
