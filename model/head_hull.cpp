#include "model/head_hull.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::model {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kSearchMm = 300;  // how far from the head frame's origin a silhouette is searched

// One horizontal slice of the head: its height and the superellipse's centre and semi-axes.
struct Slice {
  double y = 0, xc = 0, zc = 0, a = 0, b = 0;
};

bool inside(const cv::Mat& mask, const capture::CameraModel& camera, const Eigen::Vector3d& p) {
  const Eigen::Vector2d px = capture::project(camera, p);
  if (!std::isfinite(px.x()) || !std::isfinite(px.y())) return false;
  const int c = int(std::floor(px.x())), r = int(std::floor(px.y()));
  return c >= 0 && r >= 0 && c < mask.cols && r < mask.rows && mask.at<uchar>(r, c) != 0;
}

// The run of consecutive inside samples (1 mm apart over [-kSearchMm, kSearchMm]) that holds
// `ref`, or else the one whose centre lies nearest it within 30 mm; nullopt when there is none.
template <typename Inside>
std::optional<std::pair<double, double>> run_at(const Inside& is_inside, double ref) {
  std::optional<std::pair<double, double>> best;
  double best_gap = 30;
  double start = 0;
  bool in = false;
  for (double t = -kSearchMm; t <= kSearchMm + 1; t += 1) {
    const bool now = t <= kSearchMm && is_inside(t);
    if (now && !in) start = t;
    if (!now && in) {
      const double lo = start, hi = t - 1;
      const double gap = (ref >= lo && ref <= hi) ? 0 : std::abs(0.5 * (lo + hi) - ref);
      if (gap < best_gap ||
          (gap == 0 && best_gap == 0 && best && hi - lo > best->second - best->first)) {
        best_gap = gap;
        best = {lo, hi};
      }
    }
    in = now;
  }
  return best;
}

// The front silhouette's run in width at height y and depth z around x_ref.
std::optional<std::pair<double, double>> width_run_at(const cv::Mat& front,
                                                      const capture::CameraModel& camera, double y,
                                                      double z, double x_ref) {
  return run_at([&](double x) { return inside(front, camera, {x, y, z}); }, x_ref);
}

// The slice at height y around the reference centre (x_ref, z_ref): the side silhouette's run
// in depth, then the front silhouette's run in width at that run's middle.
std::optional<Slice> slice_at(const cv::Mat& front, const cv::Mat& side,
                              const capture::RigCalibration& rig, double y, double x_ref,
                              double z_ref) {
  const auto depth_run = run_at(
      [&](double z) {
        return inside(side, rig.side, {x_ref, y, z});
      },
      z_ref);
  if (!depth_run) return std::nullopt;
  const double zc = 0.5 * (depth_run->first + depth_run->second);
  const auto width_run = width_run_at(front, rig.front, y, zc, x_ref);
  if (!width_run) return std::nullopt;
  Slice s;
  s.y = y;
  s.xc = 0.5 * (width_run->first + width_run->second);
  s.zc = zc;
  s.a = 0.5 * (width_run->second - width_run->first + 1);
  s.b = 0.5 * (depth_run->second - depth_run->first + 1);
  if (s.a < 3 || s.b < 3) return std::nullopt;
  return s;
}

// Where the face mesh is: the mean of its vertices and its lowest height (head frame, mm).
struct FaceSpan {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double bottom = 0;
};

FaceSpan face_span(const mesh::TriMesh& face) {
  FaceSpan f;
  f.bottom = face.vertices.front().y();
  for (const auto& v : face.vertices) {
    f.mean += v;
    f.bottom = std::min(f.bottom, v.y());
  }
  f.mean /= double(face.vertices.size());
  return f;
}

// The slices from the top of the head down to the collar, top first.
std::vector<Slice> head_slices(const cv::Mat& front, const cv::Mat& side,
                               const capture::RigCalibration& rig, const FaceSpan& face,
                               const HullOptions& o) {
  const Eigen::Vector3d& mean = face.mean;
  const double face_bottom = face.bottom;
  std::vector<Slice> up, down;
  double x_ref = mean.x(), z_ref = mean.z();
  for (double y = mean.y(); y < mean.y() + kSearchMm; y += o.slice_mm) {
    const auto s = slice_at(front, side, rig, y, x_ref, z_ref);
    if (!s) break;
    up.push_back(*s);
    x_ref = s->xc;
    z_ref = s->zc;
  }
  if (up.empty()) return {};
  // Above the side silhouette's top (a pair not taken at one height, hair the side photo's cut
  // lost) the front silhouette may still hold head: the slices go on with its width and a depth
  // that shrinks with that width, so the head drawn covers the front photo's whole head.
  for (double y = up.back().y + o.slice_mm; y < mean.y() + kSearchMm; y += o.slice_mm) {
    const Slice& last = up.back();
    const auto width_run = width_run_at(front, rig.front, y, last.zc, x_ref);
    if (!width_run) break;
    Slice s = last;
    s.y = y;
    s.xc = 0.5 * (width_run->first + width_run->second);
    s.a = 0.5 * (width_run->second - width_run->first + 1);
    if (s.a < 3) break;
    s.b = last.b * std::min(1.0, s.a / last.a);
    up.push_back(s);
    x_ref = s.xc;
  }
  x_ref = up.front().xc;
  z_ref = up.front().zc;
  double narrowest = std::numeric_limits<double>::infinity();
  std::optional<Slice> narrow;  // the last slice before the front silhouette widens
  bool widened = false;
  std::optional<Slice> neck;  // the neck's last slice before the shoulders
  for (double y = mean.y() - o.slice_mm; y > face_bottom - o.max_neck_mm; y -= o.slice_mm) {
    auto s = slice_at(front, side, rig, y, x_ref, z_ref);
    if (!s && !neck) break;
    // Below the face's middle the neck is narrower than the jaw: a slice much wider than the
    // narrowest since reaches the shoulders (or hair on them). On a short neck that happens
    // above the chin, beside the jaw; from there the slices keep the side photo's depth but the
    // narrow slice's width, and below the chin the neck goes on as its last slice (the body
    // stays the photo's, render::CompositeOptions).
    if (s && !widened) {
      narrowest = std::min(narrowest, s->a);
      if (s->a > o.collar_widening * narrowest)
        widened = true;
      else
        narrow = *s;
    }
    if (y < face_bottom && (neck || !s || widened)) {
      if (!neck) neck = down.empty() ? *s : down.back();
      s = *neck;
      s->y = y;
    } else if (widened && narrow) {
      s->xc = narrow->xc;
      s->a = std::min(s->a, narrow->a);
    }
    down.push_back(*s);
    x_ref = s->xc;
    z_ref = s->zc;
  }
  std::vector<Slice> slices(up.rbegin(), up.rend());
  slices.insert(slices.end(), down.begin(), down.end());
  return slices;
}

// Radius of the superellipse |x/a|^n + |z/b|^n = 1 along the direction (sin t, cos t).
double superellipse_radius(double a, double b, double n, double t) {
  const double s = std::abs(std::sin(t)) / a, c = std::abs(std::cos(t)) / b;
  return std::pow(std::pow(s, n) + std::pow(c, n), -1.0 / n);
}

// Where the face mesh lies around the slices: per (slice, angle) cell, the smallest of the face's
// outermost radii around it (hollow_mm, hollow_deg), 0 where the face does not reach. Columns are
// shifted by half a turn so the face (angle 0) lies mid-grid.
cv::Mat face_radii(const mesh::TriMesh& face, const std::vector<Slice>& slices,
                   const HullOptions& o, cv::Mat* outermost = nullptr) {
  const int n = o.angles;
  cv::Mat grid(int(slices.size()), n, CV_32F, cv::Scalar(0));
  const double y0 = slices.front().y;
  auto splat = [&](const Eigen::Vector3d& p) {
    const int j = int(std::lround((y0 - p.y()) / o.slice_mm));
    if (j < 0 || j >= grid.rows) return;
    const Slice& s = slices[size_t(j)];
    const double dx = p.x() - s.xc, dz = p.z() - s.zc;
    const int i = int(std::lround(std::atan2(dx, dz) / (2 * kPi) * n));
    const int col = ((i + n / 2) % n + n) % n;
    float& cell = grid.at<float>(j, col);
    cell = std::max(cell, float(std::hypot(dx, dz)));
  };
  for (const auto& t : face.triangles) {
    const Eigen::Vector3d& a = face.vertices[size_t(t[0])];
    const Eigen::Vector3d& b = face.vertices[size_t(t[1])];
    const Eigen::Vector3d& c = face.vertices[size_t(t[2])];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int k = std::max(1, int(std::ceil(longest / 0.8)));
    for (int u = 0; u <= k; ++u)
      for (int v = 0; u + v <= k; ++v)
        splat(a + (b - a) * (double(u) / k) + (c - a) * (double(v) / k));
  }
  // Cells between samples (a coarse triangle, a cell boundary) take their neighbours' radius.
  cv::Mat covered = grid > 0, closed, grown;
  cv::morphologyEx(covered, closed, cv::MORPH_CLOSE, cv::Mat::ones(3, 3, CV_8U));
  cv::dilate(grid, grown, cv::Mat::ones(3, 3, CV_8U));
  grown.copyTo(grid, closed & ~covered);
  // The smallest radius around each cell (the face's hollows: eye sockets, the sides of the nose):
  // a hull triangle between two vertices placed by it stays behind the face between them too.
  const int half_rows = std::max(1, int(std::lround(o.hollow_mm / o.slice_mm)));
  const int half_cols = std::max(1, int(std::lround(o.hollow_deg / 360.0 * n)));
  if (outermost) *outermost = grid.clone();
  cv::Mat lowest = grid.clone();
  lowest.setTo(std::numeric_limits<float>::max(), grid <= 0);
  cv::erode(lowest, lowest, cv::Mat::ones(2 * half_rows + 1, 2 * half_cols + 1, CV_8U),
            cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  lowest.setTo(0, grid <= 0);
  return lowest;
}

}  // namespace

void HullOptions::check() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("hull options: " + what); };
  if (!(slice_mm >= 0.5 && slice_mm <= 20)) bad("slice_mm must be in [0.5, 20]");
  if (angles < 16 || angles > 1024) bad("angles must be in [16, 1024]");
  if (!(front_exponent >= 1 && front_exponent <= 10)) bad("front_exponent must be in [1, 10]");
  if (!(back_exponent >= 1 && back_exponent <= 10)) bad("back_exponent must be in [1, 10]");
  if (!(face_inset_mm >= 0 && face_inset_mm <= 50)) bad("face_inset_mm must be in [0, 50]");
  if (!(hollow_mm >= 0 && hollow_mm <= 100)) bad("hollow_mm must be in [0, 100]");
  if (!(hollow_deg >= 0 && hollow_deg <= 90)) bad("hollow_deg must be in [0, 90]");
  if (!(face_slope > 0 && face_slope <= 100)) bad("face_slope must be in (0, 100]");
  if (!(collar_widening > 1 && collar_widening <= 10)) bad("collar_widening must be in (1, 10]");
  if (!(max_neck_mm >= 0 && max_neck_mm <= 500)) bad("max_neck_mm must be in [0, 500]");
}

HeadHull head_hull(const cv::Mat& front_silhouette, const cv::Mat& side_silhouette,
                   const capture::RigCalibration& photo_rig, const mesh::TriMesh& face,
                   const HullOptions& o) {
  o.check();
  for (auto [name, mask, camera] : {std::tuple{"front", &front_silhouette, &photo_rig.front},
                                    std::tuple{"side", &side_silhouette, &photo_rig.side}}) {
    const std::string what = std::string("head hull: the ") + name + " silhouette";
    if (mask->empty()) throw std::invalid_argument(what + " is empty");
    if (mask->type() != CV_8UC1) throw std::invalid_argument(what + " is not 8-bit single-channel");
    if (mask->cols != camera->width || mask->rows != camera->height)
      throw std::invalid_argument(
          what + " is " + std::to_string(mask->cols) + "x" + std::to_string(mask->rows) +
          ", its camera " + std::to_string(camera->width) + "x" + std::to_string(camera->height));
  }
  mesh::check_mesh(face, "head hull: the face mesh");

  const FaceSpan span = face_span(face);
  const std::vector<Slice> slices =
      head_slices(front_silhouette, side_silhouette, photo_rig, span, o);
  if (slices.size() < 8) return {};
  HeadHull hull;
  Eigen::Vector2d neck = Eigen::Vector2d::Zero();
  int neck_slices = 0;
  for (const Slice& s : slices)
    if (s.y <= span.bottom - 10 && s.y >= span.bottom - 40)
      neck += Eigen::Vector2d(s.xc, s.zc), ++neck_slices;
  if (neck_slices > 0) {
    neck /= neck_slices;
    hull.pivot = {neck.x(), 0.5 * (span.mean.y() + span.bottom), neck.y()};
  }
  const int n = o.angles, rows = int(slices.size());
  cv::Mat outermost;
  const cv::Mat radii = face_radii(face, slices, o, &outermost);

  // Distance (mm) from every cell to the face's nearest cell, and that cell's radius.
  cv::Mat outside = radii <= 0, dist, labels, inside_labels;
  std::vector<float> label_radius(size_t(rows) * size_t(n) + 1, 0.f);
  std::vector<cv::Point> label_cell(label_radius.size()), edge_cell(label_radius.size());
  const bool any_face = cv::countNonZero(~outside) > 0;
  if (any_face) {
    cv::distanceTransform(outside, dist, labels, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    // And from every covered cell to the nearest cell the face leaves uncovered.
    cv::distanceTransform(~outside, dist, inside_labels, cv::DIST_L2, cv::DIST_MASK_5,
                          cv::DIST_LABEL_PIXEL);
    for (int j = 0; j < rows; ++j)
      for (int c = 0; c < n; ++c)
        if (outside.at<uchar>(j, c)) {
          const size_t l = size_t(inside_labels.at<int>(j, c));
          if (l < edge_cell.size()) edge_cell[l] = {c, j};
        }
    for (int j = 0; j < rows; ++j)
      for (int c = 0; c < n; ++c)
        if (!outside.at<uchar>(j, c)) {
          const size_t l = size_t(labels.at<int>(j, c));
          if (l < label_radius.size()) {
            label_radius[l] = radii.at<float>(j, c);
            label_cell[l] = {c, j};
          }
        }
  }

  mesh::TriMesh& m = hull.mesh;
  m.vertices.reserve(size_t(rows) * size_t(n) + 2);
  for (int j = 0; j < rows; ++j) {
    const Slice& s = slices[size_t(j)];
    for (int i = 0; i < n; ++i) {
      const double t = 2 * kPi * i / n;
      double r =
          superellipse_radius(s.a, s.b, std::cos(t) >= 0 ? o.front_exponent : o.back_exponent, t);
      const int col = (i + n / 2) % n;
      if (any_face) {
        const float face_r = radii.at<float>(j, col);
        if (face_r > 0) {
          // The inset fades over the last 4 mm inside the face's edge, so the hull meets the
          // edge flush: a strip behind the edge would be hidden from the front photo by the
          // face yet seen past the edge from above or below.
          const size_t l = size_t(inside_labels.at<int>(j, col));
          double d = 4;
          if (l < edge_cell.size())
            d = std::hypot((col - edge_cell[l].x) * 2 * kPi / n * face_r,
                           (j - edge_cell[l].y) * o.slice_mm);
          const double w = std::clamp((d - o.slice_mm) / std::max(4.0, 2 * o.slice_mm), 0.0, 1.0);
          r = std::min(r, w * (face_r - o.face_inset_mm) + (1 - w) * outermost.at<float>(j, col));
        } else {
          const size_t l = size_t(labels.at<int>(j, col));
          if (l < label_radius.size()) {
            const cv::Point cell = label_cell[l];
            const double along = (col - cell.x) * 2 * kPi / n * r;
            const double down = (j - cell.y) * o.slice_mm;
            const double d = std::hypot(along, down);
            // The inset fades over the first 4 mm past the face's edge, so the hull meets the
            // edge rather than leaving a step behind it.
            const double inset = o.face_inset_mm * std::max(0.0, 1 - d / 4);
            r = std::min(r, label_radius[l] - inset + o.face_slope * d);
          }
        }
      }
      r = std::max(r, 1.0);
      m.vertices.emplace_back(s.xc + r * std::sin(t), s.y, s.zc + r * std::cos(t));
    }
  }
  const int top = int(m.vertices.size());
  m.vertices.emplace_back(slices.front().xc, slices.front().y + 0.5 * o.slice_mm,
                          slices.front().zc);
  const int bottom = int(m.vertices.size());
  m.vertices.emplace_back(slices.back().xc, slices.back().y - 0.5 * o.slice_mm, slices.back().zc);

  auto v = [n](int j, int i) { return j * n + (i % n); };
  for (int j = 0; j + 1 < rows; ++j)
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({v(j, i), v(j + 1, i), v(j, i + 1)});
      m.triangles.push_back({v(j, i + 1), v(j + 1, i), v(j + 1, i + 1)});
    }
  for (int i = 0; i < n; ++i) {
    m.triangles.push_back({top, v(0, i), v(0, i + 1)});
    m.triangles.push_back({bottom, v(rows - 1, i + 1), v(rows - 1, i)});
  }
  return hull;
}

mesh::TriMesh combined(const mesh::TriMesh& a, const mesh::TriMesh& b) {
  mesh::TriMesh m = a;
  const int offset = int(a.vertices.size());
  m.vertices.insert(m.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles)
    m.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  const bool colours = !a.colors.empty() && !b.colors.empty();
  const bool uvs = !a.uvs.empty() && !b.uvs.empty();
  if (colours)
    m.colors.insert(m.colors.end(), b.colors.begin(), b.colors.end());
  else
    m.colors.clear();
  if (uvs) {
    m.uvs.insert(m.uvs.end(), b.uvs.begin(), b.uvs.end());
  } else {
    m.uvs.clear();
    m.texture.release();
  }
  return m;
}

}  // namespace orthoface::model
