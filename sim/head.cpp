#include "sim/head.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace orthoface::sim {

namespace {

void check_range(const char* name, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi)
    throw std::invalid_argument("HeadParams: " + std::string(name) + " = " + std::to_string(v) +
                                " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) +
                                "]");
}

}  // namespace

void HeadParams::check() const {
  check_range("head_width", head_width, 100, 220);
  check_range("head_depth", head_depth, 140, 260);
  check_range("head_height", head_height, 170, 300);
  check_range("nose_length", nose_length, 30, 75);
  check_range("nose_projection", nose_projection, 8, 40);
  check_range("nose_width", nose_width, 22, 55);
  check_range("mouth_width", mouth_width, 32, 75);
  check_range("lip_fullness", lip_fullness, 0.2, 2.5);
  check_range("chin_projection", chin_projection, -15, 15);
  check_range("chin_height", chin_height, 28, 65);
  check_range("jaw_width", jaw_width, 70, 145);
  check_range("eye_spacing", eye_spacing, 45, 85);
  check_range("eye_width", eye_width, 18, 40);
  check_range("brow_ridge", brow_ridge, 0, 14);
  check_range("ear_height", ear_height, -20, 20);
  check_range("ear_size", ear_size, 40, 85);
  check_range("ear_protrusion", ear_protrusion, 3, 30);
  check_range("cheek_fullness", cheek_fullness, 0, 1);
  check_range("neck_width", neck_width, 70, 170);
  check_range("neck_length", neck_length, 40, 160);
  check_range("skin_tone", skin_tone, 0, 1);
  check_range("skin_redness", skin_redness, 0, 1);
  check_range("hair_darkness", hair_darkness, 0, 1);
  for (int k = 0; k < 3; ++k) check_range("iris_rgb", iris_rgb[k], 0, 1);
  check_range("asymmetry", asymmetry, 0, 1);
  // Features must fit on the face: the eyes inside the head, the jaw inside the skull.
  if (eye_spacing + eye_width > 0.75 * head_width)
    throw std::invalid_argument("HeadParams: eyes (eye_spacing + eye_width) wider than the head");
  if (jaw_width > head_width)
    throw std::invalid_argument("HeadParams: jaw_width larger than head_width");
  if (mouth_width > jaw_width - 20)
    throw std::invalid_argument("HeadParams: mouth_width too large for jaw_width");
}

void HeadOptions::check() const {
  if (rings > 0 || segments > 0) {
    if (rings < 16 || rings > 2000 || segments < 16 || segments > 4000 || segments % 2 != 0)
      throw std::invalid_argument(
          "HeadOptions: rings must be in [16, 2000] and segments an even number in [16, 4000], "
          "got " +
          std::to_string(rings) + " x " + std::to_string(segments));
  } else if (target_triangles < 800 || target_triangles > 4000000) {
    throw std::invalid_argument("HeadOptions: target_triangles must be in [800, 4000000], got " +
                                std::to_string(target_triangles));
  }
  if (texture_size < 64 || texture_size > 8192)
    throw std::invalid_argument("HeadOptions: texture_size must be in [64, 8192], got " +
                                std::to_string(texture_size));
}

HeadParams head_params(int seed) {
  if (seed < 0)
    throw std::invalid_argument("head_params: seed must be >= 0, got " + std::to_string(seed));
  HeadParams p;
  if (seed == 0) return p;
  std::mt19937 rng(0x0face + static_cast<unsigned>(seed) * 7919u);
  std::normal_distribution<double> n01(0.0, 1.0);
  // Normal around the average, clamped to the realistic range (about +-2 sigma).
  auto vary = [&](double mean, double sigma, double lo, double hi) {
    return std::clamp(mean + sigma * n01(rng), lo, hi);
  };
  p.head_width = vary(152, 6, 140, 165);
  p.head_depth = vary(195, 7, 180, 210);
  p.head_height = vary(235, 7, 220, 250);
  p.nose_length = vary(50, 3.5, 44, 58);
  p.nose_projection = vary(20, 2.5, 15, 26);
  p.nose_width = vary(35, 3, 30, 42);
  p.mouth_width = vary(50, 3.5, 44, 58);
  p.lip_fullness = vary(1.0, 0.2, 0.6, 1.5);
  p.chin_projection = vary(0, 3, -6, 6);
  p.chin_height = vary(45, 3.5, 38, 52);
  p.jaw_width = vary(105, 6, 92, 120);
  p.eye_spacing = vary(63, 3, 57, 70);
  p.eye_width = vary(29, 1.5, 26, 32);
  p.brow_ridge = vary(4, 1.8, 1, 8);
  p.ear_height = vary(0, 4, -8, 8);
  p.ear_size = vary(62, 4, 54, 70);
  p.ear_protrusion = vary(14, 3, 8, 20);
  p.cheek_fullness = vary(0.5, 0.25, 0, 1);
  p.neck_width = vary(105, 7, 92, 120);
  p.neck_length = vary(75, 8, 60, 90);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  p.skin_tone = u01(rng);
  p.skin_redness = u01(rng);
  p.hair_darkness = u01(rng);
  const Eigen::Vector3d irises[4] = {
      {0.35, 0.22, 0.12}, {0.25, 0.45, 0.65}, {0.30, 0.45, 0.25}, {0.18, 0.12, 0.08}};
  p.iris_rgb = irises[std::uniform_int_distribution<int>(0, 3)(rng)];
  return p;
}

std::optional<SilhouetteExtremes> silhouette_extremes(const Head& head, double y_mm) {
  return silhouette_extremes(head.mesh, y_mm);
}

std::optional<SilhouetteExtremes> silhouette_extremes(const mesh::TriMesh& mesh, double y_mm) {
  if (!std::isfinite(y_mm)) throw std::invalid_argument("silhouette_extremes: y is not finite");
  const auto& v = mesh.vertices;
  SilhouetteExtremes e;
  e.min_x = e.min_z = std::numeric_limits<double>::infinity();
  e.max_x = e.max_z = -std::numeric_limits<double>::infinity();
  bool any = false;
  auto add = [&](const Eigen::Vector3d& p) {
    any = true;
    e.min_x = std::min(e.min_x, p.x());
    e.max_x = std::max(e.max_x, p.x());
    e.min_z = std::min(e.min_z, p.z());
    e.max_z = std::max(e.max_z, p.z());
  };
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& a = v.at(t[k]);
      const Eigen::Vector3d& b = v.at(t[(k + 1) % 3]);
      const double da = a.y() - y_mm, db = b.y() - y_mm;
      if (da == 0) add(a);
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) add(a + (b - a) * (da / (da - db)));
    }
  }
  if (!any) return std::nullopt;
  return e;
}

}  // namespace orthoface::sim
