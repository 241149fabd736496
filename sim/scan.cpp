#include "sim/scan.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <stdexcept>
#include <vector>

#include "mesh/mesh_io.h"

namespace orthoface::sim {

namespace {

constexpr double kTopToTragusMm = 125;  // vertex to the ear canal level, adult average

// Widest section (x extent) for heights in [y_lo, y_hi].
double max_width(const mesh::TriMesh& m, double y_lo, double y_hi) {
  double w = 0;
  for (int k = 0; k <= 40; ++k) {
    const auto e = silhouette_extremes(m, y_lo + (y_hi - y_lo) * k / 40.0);
    if (e) w = std::max(w, e->max_x - e->min_x);
  }
  return w;
}

// Front-most point of the x = 0 section per 0.25 mm height bin: (y, z), descending y.
std::vector<Eigen::Vector2d> midline_profile(const mesh::TriMesh& m) {
  double y_lo = std::numeric_limits<double>::infinity(), y_hi = -y_lo;
  for (const auto& v : m.vertices) {
    y_lo = std::min(y_lo, v.y());
    y_hi = std::max(y_hi, v.y());
  }
  constexpr double kBin = 0.25;
  const int n = static_cast<int>((y_hi - y_lo) / kBin) + 1;
  std::vector<double> zmax(n, -std::numeric_limits<double>::infinity());
  auto add = [&](const Eigen::Vector3d& p) {
    const int b = std::clamp(static_cast<int>((y_hi - p.y()) / kBin), 0, n - 1);
    zmax[b] = std::max(zmax[b], p.z());
  };
  // Each triangle crossing x = 0 contributes a segment of the section; sample it per bin.
  for (const auto& t : m.triangles) {
    Eigen::Vector3d ends[3];
    int n_ends = 0;
    for (int k = 0; k < 3 && n_ends < 2; ++k) {
      const Eigen::Vector3d& a = m.vertices[t[k]];
      const Eigen::Vector3d& b = m.vertices[t[(k + 1) % 3]];
      if (a.x() == 0)
        ends[n_ends++] = a;
      else if ((a.x() < 0) != (b.x() < 0) && b.x() != 0)
        ends[n_ends++] = a + (b - a) * (a.x() / (a.x() - b.x()));
    }
    if (n_ends < 2) continue;
    const Eigen::Vector3d &p = ends[0], &q = ends[1];
    const int steps = 1 + static_cast<int>(std::abs(p.y() - q.y()) / (0.5 * kBin));
    for (int s = 0; s <= steps; ++s) add(p + (q - p) * (static_cast<double>(s) / steps));
  }
  std::vector<Eigen::Vector2d> out;
  for (int b = 0; b < n; ++b)
    if (std::isfinite(zmax[b])) out.emplace_back(y_hi - (b + 0.5) * kBin, zmax[b]);
  return out;
}

using Profile = std::vector<Eigen::Vector2d>;

// Index of the profile sample maximising score over heights [y_lo, y_hi]; throws if none.
size_t best(const Profile& p, double y_lo, double y_hi,
            const std::function<double(const Eigen::Vector2d&)>& score, const char* what) {
  size_t arg = p.size();
  double top = -std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < p.size(); ++k)
    if (p[k].x() >= y_lo && p[k].x() <= y_hi && score(p[k]) > top) {
      top = score(p[k]);
      arg = k;
    }
  if (arg == p.size())
    throw std::runtime_error(std::string("scan_profile_landmarks: no profile for ") + what);
  return arg;
}

// First sample below index `from` with height in [y_hi >= y >= y_lo] whose z is the maximum
// within +-window mm (a local peak of the profile); throws if there is none.
size_t next_peak(const Profile& p, size_t from, double y_hi, double y_lo, double window,
                 const char* what) {
  for (size_t k = from + 1; k < p.size(); ++k) {
    if (p[k].x() > y_hi) continue;
    if (p[k].x() < y_lo) break;
    bool peak = true;
    for (size_t q = 0; q < p.size() && peak; ++q)
      if (std::abs(p[q].x() - p[k].x()) <= window && p[q].y() > p[k].y()) peak = false;
    if (peak) return k;
  }
  throw std::runtime_error(std::string("scan_profile_landmarks: no profile peak for ") + what);
}

Eigen::Vector3d on_midline(const Eigen::Vector2d& yz) { return {0, yz.x(), yz.y()}; }

// Widest point at height y on side `dir` (+1: +x) among section points with z >= z_min.
Eigen::Vector3d widest_point(const mesh::TriMesh& m, double y, double z_min, double dir) {
  Eigen::Vector3d best_p(0, y, z_min);
  double best_x = -std::numeric_limits<double>::infinity();
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& a = m.vertices[t[k]];
      const Eigen::Vector3d& b = m.vertices[t[(k + 1) % 3]];
      if ((a.y() < y) == (b.y() < y) || a.y() == b.y()) continue;
      const Eigen::Vector3d p = a + (b - a) * ((y - a.y()) / (b.y() - a.y()));
      if (p.z() >= z_min && dir * p.x() > best_x) {
        best_x = dir * p.x();
        best_p = p;
      }
    }
  return best_p;
}

// The front-most surface point at (x, y) (a ray along -z), or nullopt.
std::optional<Eigen::Vector3d> front_point(const mesh::TriMesh& m, double x, double y) {
  std::optional<Eigen::Vector3d> hit;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(det) < 1e-12) continue;
    const double dx = x - a.x(), dy = y - a.y();
    const double l1 = (dx * (c - a).y() - dy * (c - a).x()) / det;
    const double l2 = ((b - a).x() * dy - (b - a).y() * dx) / det;
    if (l1 < 0 || l2 < 0 || l1 + l2 > 1) continue;
    const Eigen::Vector3d p = (1 - l1 - l2) * a + l1 * b + l2 * c;
    if (!hit || p.z() > hit->z()) hit = p;
  }
  return hit;
}

// Landmarks picked by eye on Map-COL.jpg (1024 x 1024, pixel column, row from the top), on
// renders of the scan: eyes closed, so eye centres are the middle of the closed lid line.
struct Pick {
  const char* name;
  double col, row;
};
constexpr Pick kLeePerrySmithPicks[] = {
    {"eye_right_inner", 464, 302},  {"eye_right_outer", 406, 305},  {"eye_left_inner", 558, 302},
    {"eye_left_outer", 620, 305},   {"brow_right_inner", 468, 269}, {"brow_right_center", 428, 263},
    {"brow_right_outer", 385, 276}, {"brow_left_inner", 531, 267},  {"brow_left_center", 585, 261},
    {"brow_left_outer", 635, 276},  {"mouth_right", 450, 472},      {"mouth_left", 570, 473},
    {"alar_right", 470, 410},       {"alar_left", 543, 407},        {"ear_right_top", 238, 320},
    {"ear_left_top", 790, 320},     {"ear_right_tragus", 290, 404}, {"ear_left_tragus", 740, 404}};

}  // namespace

void ScanOptions::check() const {
  if (!std::isfinite(mm_per_unit) || mm_per_unit < 0)
    throw std::invalid_argument("ScanOptions: mm_per_unit must be >= 0 (0 = estimate)");
  if (!std::isfinite(head_width_mm) || head_width_mm < 80 || head_width_mm > 250)
    throw std::invalid_argument("ScanOptions: head_width_mm must be in [80, 250]");
}

std::map<std::string, Eigen::Vector3d> scan_profile_landmarks(const mesh::TriMesh& mesh) {
  const Profile p = midline_profile(mesh);
  if (p.size() < 100)
    throw std::runtime_error("scan_profile_landmarks: the mesh does not cross x = 0");
  const double top = p.front().x();
  auto z = [](const Eigen::Vector2d& s) { return s.y(); };
  auto neg_z = [](const Eigen::Vector2d& s) { return -s.y(); };
  const size_t tip = best(p, top - 200, top - 90, z, "the nose tip");
  const double yt = p[tip].x();
  const size_t bridge = best(p, yt + 15, yt + 50, neg_z, "the nose bridge");
  // Below the tip the profile has local maxima at the lips and the chin (in that order).
  const size_t lu = next_peak(p, tip, yt - 8, yt - 60, 4.0, "the upper lip");
  const size_t ll = next_peak(p, lu, p[lu].x() - 3, p[lu].x() - 25, 4.0, "the lower lip");
  const size_t chin = next_peak(p, ll, p[ll].x() - 8, p[ll].x() - 55, 8.0, "the chin");
  const Eigen::Vector2d T = p[tip], L = p[lu];
  Eigen::Vector2d nrm(-(L - T).y(), (L - T).x());  // in (y, z): perpendicular to the chord
  if (nrm.y() > 0) nrm = -nrm;                     // toward the inside of the face (smaller z)
  nrm.normalize();
  const size_t sub = best(
      p, L.x(), T.x(), [&](const Eigen::Vector2d& s) { return (s - T).dot(nrm); }, "the subnasale");
  const size_t cb = best(
      p, p[chin].x() - 35, p[chin].x(), [](const Eigen::Vector2d& s) { return s.y() - s.x(); },
      "the chin bottom");
  const double y_fh = p[bridge].x() + 65;
  const size_t fh = best(p, y_fh - 0.5, y_fh + 0.5, z, "the forehead");
  return {{"nose_tip", on_midline(p[tip])},   {"nose_bridge", on_midline(p[bridge])},
          {"lip_upper", on_midline(p[lu])},   {"lip_lower", on_midline(p[ll])},
          {"chin", on_midline(p[chin])},      {"subnasale", on_midline(p[sub])},
          {"chin_bottom", on_midline(p[cb])}, {"forehead_top", on_midline(p[fh])}};
}

std::optional<Eigen::Vector3d> point_at_uv(const mesh::TriMesh& m, const Eigen::Vector2d& uv) {
  if (m.uvs.size() != m.vertices.size() || m.uvs.empty())
    throw std::invalid_argument("point_at_uv: the mesh has no texture coordinates");
  for (const auto& t : m.triangles) {
    const Eigen::Vector2d a = m.uvs[t[0]], b = m.uvs[t[1]], c = m.uvs[t[2]];
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(det) < 1e-14) continue;
    const Eigen::Vector2d d = uv - a;
    const double l1 = (d.x() * (c - a).y() - d.y() * (c - a).x()) / det;
    const double l2 = ((b - a).x() * d.y() - (b - a).y() * d.x()) / det;
    if (l1 >= -1e-9 && l2 >= -1e-9 && l1 + l2 <= 1 + 1e-9)
      return (1 - l1 - l2) * m.vertices[t[0]] + l1 * m.vertices[t[1]] + l2 * m.vertices[t[2]];
  }
  return std::nullopt;
}

Head load_scan(const std::string& path, const ScanOptions& options) {
  options.check();
  mesh::MeshReadOptions ro;
  ro.texture_path = options.texture_path;
  ro.gltf_uv_bottom_origin = options.gltf_uv_bottom_origin;
  Head head;
  head.mesh = mesh::read_mesh(path, ro);
  head.name = std::filesystem::path(path).stem().string() + " scan";
  head.landmarks_picked = true;
  auto& v = head.mesh.vertices;
  double top = -std::numeric_limits<double>::infinity(), bottom = -top;
  for (const auto& p : v) {
    top = std::max(top, p.y());
    bottom = std::min(bottom, p.y());
  }
  double scale = options.mm_per_unit;
  if (scale == 0) {
    // Skull breadth: first guess from the upper part, then 40..100 mm below the top.
    const double h = top - bottom;
    const double w0 = max_width(head.mesh, top - 0.3 * h, top - 0.1 * h);
    if (!(w0 > 0)) throw std::runtime_error(path + ": cannot estimate the head width for scaling");
    const double s0 = options.head_width_mm / w0;
    scale = options.head_width_mm / max_width(head.mesh, top - 85 / s0, top - 35 / s0);
  }
  for (auto& p : v) p *= scale;
  const double y0 = top * scale - kTopToTragusMm;
  const auto e = silhouette_extremes(head.mesh, y0);
  if (!e)
    throw std::runtime_error(path + ": the scan is shorter than a head (" +
                             std::to_string((top - bottom) * scale) + " mm)");
  const Eigen::Vector3d origin(0.5 * (e->min_x + e->max_x), y0, 0.5 * (e->min_z + e->max_z));
  for (auto& p : v) p -= origin;
  head.landmarks = scan_profile_landmarks(head.mesh);
  return head;
}

}  // namespace orthoface::sim

namespace orthoface::sim {

Head lee_perry_smith_head(const std::string& data_dir) {
  namespace fs = std::filesystem;
  const fs::path dir(data_dir);
  ScanOptions o;
  o.texture_path = (dir / "Map-COL.jpg").string();
  o.gltf_uv_bottom_origin = true;  // SOURCE.md: its TEXCOORD_0 has v = 0 at the bottom row
  const fs::path glb = dir / "LeePerrySmith.glb", obj = dir / "LeePerrySmith.obj";
  Head head = load_scan((fs::exists(glb) || !fs::exists(obj) ? glb : obj).string(), o);
  head.name = "Lee Perry-Smith scan";
  const int w = head.mesh.texture.cols, h = head.mesh.texture.rows;
  for (const Pick& pk : kLeePerrySmithPicks) {
    const Eigen::Vector2d uv((pk.col + 0.5) / w, 1 - (pk.row + 0.5) / h);
    const auto p = point_at_uv(head.mesh, uv);
    if (!p)
      throw std::runtime_error(data_dir + ": picked landmark " + pk.name +
                               " is off the texture map");
    head.landmarks[pk.name] = *p;
  }
  for (const char* side : {"left", "right"}) {
    const std::string e = std::string("eye_") + side;
    const Eigen::Vector3d mid =
        0.5 * (head.landmarks.at(e + "_inner") + head.landmarks.at(e + "_outer"));
    const auto p = front_point(head.mesh, mid.x(), mid.y());
    if (!p) throw std::runtime_error(data_dir + ": no surface in front of the " + side + " eye");
    head.landmarks[e + "_center"] = *p;
  }
  // Cheeks: widest face points at nose-tip height, 12 mm or more in front of the tragus.
  const double y_tip = head.landmarks.at("nose_tip").y();
  head.landmarks["cheek_left"] =
      widest_point(head.mesh, y_tip, head.landmarks.at("ear_left_tragus").z() + 12, 1);
  head.landmarks["cheek_right"] =
      widest_point(head.mesh, y_tip, head.landmarks.at("ear_right_tragus").z() + 12, -1);
  // With the tragi picked, put the origin exactly between them (DESIGN.md head frame).
  const Eigen::Vector3d mid =
      0.5 * (head.landmarks.at("ear_left_tragus") + head.landmarks.at("ear_right_tragus"));
  const Eigen::Vector3d shift(0, mid.y(), mid.z());  // keep x = 0 on the midline profile
  for (auto& v : head.mesh.vertices) v -= shift;
  for (auto& [name, p] : head.landmarks) p -= shift;
  return head;
}

}  // namespace orthoface::sim
