#include "reconstruct/flank_depth.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "render/gl_util.h"

namespace orthoface::reconstruct {
namespace {

// Grey levels of a photo band-passed between `fine` and `coarse` pixels (difference of
// Gaussians), CV_32F, over the part of it the compared points reach (with a margin the coarse
// blur needs); `origin` is that part's top-left pixel in the photo.
struct BandPassed {
  cv::Mat image;
  cv::Point origin;
};

BandPassed band_pass(const cv::Mat& photo, const std::vector<Eigen::Vector2d>& reached, double fine,
                     double coarse) {
  Eigen::Vector2d lo = reached.front(), hi = reached.front();
  for (const auto& p : reached) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double margin = 3 * coarse + 2;
  const cv::Rect part =
      cv::Rect(cv::Point(int(std::floor(lo.x() - margin)), int(std::floor(lo.y() - margin))),
               cv::Point(int(std::ceil(hi.x() + margin)), int(std::ceil(hi.y() + margin)))) &
      cv::Rect(0, 0, photo.cols, photo.rows);
  BandPassed out;
  out.origin = part.tl();
  if (part.width < 2 || part.height < 2) return out;
  cv::Mat grey, f, a, b;
  if (photo.channels() == 3)
    cv::cvtColor(photo(part), grey, cv::COLOR_BGR2GRAY);
  else
    grey = photo(part);
  grey.convertTo(f, CV_32F);
  cv::GaussianBlur(f, a, cv::Size(), fine);
  cv::GaussianBlur(f, b, cv::Size(), coarse);
  out.image = a - b;
  return out;
}

// Bilinear sample at photo pixel `px`; false outside the band-passed part.
bool sample(const BandPassed& bp, const Eigen::Vector2d& px, float& out) {
  const cv::Mat& img = bp.image;
  const double x = px.x() - 0.5 - bp.origin.x, y = px.y() - 0.5 - bp.origin.y;  // centres +0.5
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  if (img.empty() || x0 < 0 || y0 < 0 || x0 + 1 >= img.cols || y0 + 1 >= img.rows) return false;
  const float fx = float(x - x0), fy = float(y - y0);
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y0 + 1);
  out =
      (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  return true;
}

double correlation(const std::vector<float>& a, const std::vector<float>& b) {
  const double n = double(a.size());
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < a.size(); ++i)
    sa += a[i], sb += b[i], saa += double(a[i]) * a[i], sbb += double(b[i]) * b[i],
        sab += double(a[i]) * b[i];
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (!(va > 0 && vb > 0)) return FlankDepth::kNaN;
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

// Pixels per mm of `camera` at head point `p` (the scale the band-pass is set in).
double px_per_mm(const capture::CameraModel& camera, const Eigen::Vector3d& p) {
  return (capture::project(camera, p + Eigen::Vector3d::UnitY()) - capture::project(camera, p))
      .norm();
}

constexpr int kEdgeRings = 4;
constexpr double kMidlineMm = 5, kMidlineRampMm = 15;

// Each vertex's distance in rings of vertices from the mesh's edge (0 on it; edges used by one
// triangle), counted up to kEdgeRings.
std::vector<int> rings_from_edge(const mesh::TriMesh& mesh,
                                 const std::vector<std::set<int>>& ring) {
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  std::vector<int> dist(mesh.vertices.size(), kEdgeRings);
  std::vector<int> front;
  for (const auto& [e, count] : uses)
    if (count == 1)
      for (int v : {e.first, e.second})
        if (dist[v] != 0) dist[v] = 0, front.push_back(v);
  for (int d = 1; d < kEdgeRings && !front.empty(); ++d) {
    std::vector<int> next;
    for (int v : front)
      for (int w : ring[v])
        if (dist[w] > d) dist[w] = d, next.push_back(w);
    front.swap(next);
  }
  return dist;
}

}  // namespace

void FlankDepthOptions::check() const {
  auto bad = [](const std::string& what) {
    throw std::invalid_argument("flank depth options: " + what);
  };
  if (!std::isfinite(min_mm) || !std::isfinite(max_mm) || min_mm > 0 || max_mm < 0)
    bad("min_mm must be <= 0 <= max_mm, both finite");
  if (!(step_mm > 0) || (max_mm - min_mm) / step_mm > 1000)
    bad("step_mm must be positive and give at most 1000 steps");
  if (!(min_gain >= 0) || !std::isfinite(min_gain)) bad("min_gain must be >= 0 and finite");
  if (!(min_cos > 0 && min_cos < 1)) bad("min_cos must be in (0, 1)");
  if (!(fine_mm > 0 && coarse_mm > fine_mm && std::isfinite(coarse_mm)))
    bad("fine_mm and coarse_mm must satisfy 0 < fine_mm < coarse_mm");
  if (min_points < 3) bad("min_points must be >= 3");
  if (!(blend_mm > 0 && std::isfinite(blend_mm))) bad("blend_mm must be positive and finite");
  if (!std::isfinite(below_max_mm) || below_max_mm < 0 || (below_max_mm - min_mm) / step_mm > 1000)
    bad("below_max_mm must be >= 0, finite and give at most 1000 steps");
}

FlankDepth fit_flank_depth(const mesh::TriMesh& mesh, const cv::Mat& front, const cv::Mat& side,
                           const capture::RigCalibration& rig, const FlankDepthOptions& o) {
  o.check();
  mesh::check_mesh(mesh, "flank depth: mesh");
  for (const auto& [photo, cam, name] :
       {std::tuple{&front, &rig.front, "front"}, std::tuple{&side, &rig.side, "side"}})
    if (photo->empty() || photo->cols != cam->width || photo->rows != cam->height ||
        (photo->type() != CV_8UC3 && photo->type() != CV_8UC1))
      throw std::invalid_argument(std::string("flank depth: the ") + name +
                                  " photo is not an 8-bit BGR or grey image of its camera's size");
  const size_t n = mesh.vertices.size();
  FlankDepth out;
  out.weight.assign(n, 0.0);
  const std::vector<Eigen::Vector3d> normals = render::gl::vertex_normals(mesh);
  const Eigen::Vector3d to_front = -capture::view_direction(rig.front);
  const Eigen::Vector3d to_side = -capture::view_direction(rig.side);
  const double full = std::sqrt(0.5);  // a normal halfway between the cameras moves fully
  std::vector<char> seen(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const double f = normals[i].dot(to_front), s = normals[i].dot(to_side);
    out.weight[i] = std::clamp(std::min(f, s) / full, 0.0, 1.0);
    seen[i] = std::min(f, s) >= o.min_cos;
  }
  // Three passes of one-ring averaging: the offset tapers smoothly into the midline and outline.
  std::vector<std::set<int>> ring(n);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ring[t[k]].insert({t[(k + 1) % 3], t[(k + 2) % 3]});
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<double> next(n);
    for (size_t i = 0; i < n; ++i) {
      double sum = out.weight[i];
      for (int j : ring[i]) sum += out.weight[j];
      next[i] = sum / double(1 + ring[i].size());
    }
    out.weight.swap(next);
  }
  // The mesh's own edge stays where it is (the head hull meets it there, and a turned view's
  // outline of the face is drawn by it): the offset grows from nothing at the edge over
  // kEdgeRings rings of vertices.
  const std::vector<int> rings = rings_from_edge(mesh, ring);
  for (size_t i = 0; i < n; ++i) out.weight[i] *= std::min(1.0, double(rings[i]) / kEdgeRings);
  // Nor does the profile (the side photo's silhouette measured it): the offset grows from
  // nothing within kMidlineMm of the midline (the vertical line through the point nearest the
  // front camera, the nose tip) to its whole over the next kMidlineRampMm, the nose's sides.
  size_t tip = 0;
  for (size_t i = 1; i < n; ++i)
    if (mesh.vertices[i].dot(to_front) > mesh.vertices[tip].dot(to_front)) tip = i;
  for (size_t i = 0; i < n; ++i) {
    const double lateral = std::abs(mesh.vertices[i].x() - mesh.vertices[tip].x());
    out.weight[i] *= std::clamp((lateral - kMidlineMm) / kMidlineRampMm, 0.0, 1.0);
  }
  // Above the nose tip the upper band's offset, below it the lower band's, blended over
  // +-blend_mm of the tip's height.
  out.below.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i)
    out.below[i] = o.bands
                       ? std::clamp((mesh.vertices[tip].y() + o.blend_mm - mesh.vertices[i].y()) /
                                        (2 * o.blend_mm),
                                    0.0, 1.0)
                       : 0.0;
  // The points compared: vertices both photos see, and the centroids of triangles all of whose
  // vertices they see (a denser sampling of the same flank).
  std::vector<Eigen::Vector3d> points;
  std::vector<double> weights, below;
  for (size_t i = 0; i < n; ++i)
    if (seen[i])
      points.push_back(mesh.vertices[i]), weights.push_back(out.weight[i]),
          below.push_back(out.below[i]);
  for (const auto& t : mesh.triangles)
    if (seen[t[0]] && seen[t[1]] && seen[t[2]]) {
      points.push_back((mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3);
      weights.push_back((out.weight[t[0]] + out.weight[t[1]] + out.weight[t[2]]) / 3);
      below.push_back((out.below[t[0]] + out.below[t[1]] + out.below[t[2]]) / 3);
    }
  out.points = int(points.size());
  if (out.points < o.min_points) return out;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p;
  centre /= double(points.size());
  const double front_scale = px_per_mm(rig.front, centre), side_scale = px_per_mm(rig.side, centre);
  const double reach_max = std::max(o.max_mm, o.bands ? o.below_max_mm : o.max_mm);
  std::vector<Eigen::Vector2d> front_reach, side_reach;  // where the points go at either limit
  for (const auto& p : points)
    for (double offset : {o.min_mm, reach_max}) {
      front_reach.push_back(capture::project(rig.front, p - offset * to_front));
      side_reach.push_back(capture::project(rig.side, p - offset * to_front));
    }
  const BandPassed front_bp =
      band_pass(front, front_reach, o.fine_mm * front_scale, o.coarse_mm * front_scale);
  const BandPassed side_bp =
      band_pass(side, side_reach, o.fine_mm * side_scale, o.coarse_mm * side_scale);
  // The correlation over the points of `band` (by their share below the nose tip), each moved by
  // its weight x ((1 - below) x up + below x down).
  enum class Band { kAll, kUpper, kLower };
  auto agreement = [&](double up, double down, Band band) {
    std::vector<float> a, b;
    a.reserve(points.size()), b.reserve(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
      if ((band == Band::kUpper && below[i] >= 0.5) || (band == Band::kLower && below[i] < 0.5))
        continue;
      const Eigen::Vector3d p =
          points[i] - weights[i] * ((1 - below[i]) * up + below[i] * down) * to_front;
      float va, vb;
      if (sample(front_bp, capture::project(rig.front, p), va) &&
          sample(side_bp, capture::project(rig.side, p), vb))
        a.push_back(va), b.push_back(vb);
    }
    return int(a.size()) >= o.min_points ? correlation(a, b) : FlankDepth::kNaN;
  };
  // The offset in min_mm..max_mm that maximises `score`, kept only when it beats offset 0 by
  // min_gain; 0 when the photos do not resolve it.
  auto search = [&](double max_mm, const auto& score) {
    const double at_zero = score(0.0);
    if (!std::isfinite(at_zero)) return 0.0;
    double best = at_zero, best_offset = 0;
    const int steps = int(std::floor((max_mm - o.min_mm) / o.step_mm + 1e-9));
    for (int k = 0; k <= steps; ++k) {
      const double offset = o.min_mm + k * o.step_mm;
      const double c = score(offset);
      if (std::isfinite(c) && c > best) best = c, best_offset = offset;
    }
    return best - at_zero >= o.min_gain ? best_offset : 0.0;
  };
  out.agreement_before = out.agreement_after = agreement(0, 0, Band::kAll);
  if (!std::isfinite(out.agreement_before)) return out;
  auto band_offset = [&](Band band, double max_mm) {
    return search(max_mm, [&](double d) { return agreement(d, d, band); });
  };
  // Each band on its own points; without bands, or for a band too small to score, the whole
  // face's one offset.
  std::optional<double> whole;
  auto whole_face = [&] { return whole ? *whole : *(whole = band_offset(Band::kAll, o.max_mm)); };
  auto scored = [&](Band band) { return o.bands && std::isfinite(agreement(0, 0, band)); };
  out.offset_mm = scored(Band::kUpper) ? band_offset(Band::kUpper, o.max_mm) : whole_face();
  out.offset_below_mm = !o.bands               ? out.offset_mm
                        : scored(Band::kLower) ? band_offset(Band::kLower, o.below_max_mm)
                                               : whole_face();
  out.agreement_after = agreement(out.offset_mm, out.offset_below_mm, Band::kAll);
  return out;
}

void move_flanks(const FlankDepth& depth, const capture::CameraModel& front_camera,
                 mesh::TriMesh& mesh, std::map<std::string, Eigen::Vector3d>& landmarks) {
  if (depth.weight.size() != mesh.vertices.size() || depth.below.size() != mesh.vertices.size())
    throw std::invalid_argument("move flanks: " + std::to_string(depth.weight.size()) + " / " +
                                std::to_string(depth.below.size()) + " weights for a mesh of " +
                                std::to_string(mesh.vertices.size()) + " vertices");
  if ((depth.offset_mm == 0 && depth.offset_below_mm == 0) || mesh.vertices.empty()) return;
  const Eigen::Vector3d to_front = -capture::view_direction(front_camera);
  for (auto& [name, p] : landmarks) {
    size_t nearest = 0;
    for (size_t i = 1; i < mesh.vertices.size(); ++i)
      if ((mesh.vertices[i] - p).squaredNorm() < (mesh.vertices[nearest] - p).squaredNorm())
        nearest = i;
    p -= depth.shift(nearest) * to_front;
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) mesh.vertices[i] -= depth.shift(i) * to_front;
}

}  // namespace orthoface::reconstruct
