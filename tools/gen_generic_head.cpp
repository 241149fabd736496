// gen_generic_head OUT.json: writes the generic head shape that model::base_mesh() starts from
// (model/data/generic_head.json, embedded into the model library at build time) from the average
// simulated head (sim::make_head(0)): the head sliced every kStepMm between forehead_top and
// chin_bottom, each slice's front half sampled by rays from (x 0, z 0) at 0..90 degrees (the
// farthest crossing), and the head's landmarks. A ctest compares its output with the file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "io/atomic_file.h"
#include "sim/head.h"

namespace {

using orthoface::mesh::TriMesh;
using Segment = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

constexpr double kStepMm = 1.0;
constexpr int kHalfRays = 46;  // rays from 0 to 90 degrees, inclusive

// The (x, z) segments where the plane at height y cuts the mesh's triangles.
std::vector<Segment> slice_segments(const TriMesh& m, double y) {
  std::vector<Segment> segs;
  for (const auto& f : m.triangles) {
    std::vector<Eigen::Vector2d> pts;
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d& a = m.vertices[f[e]];
      const Eigen::Vector3d& b = m.vertices[f[(e + 1) % 3]];
      if ((a.y() - y) * (b.y() - y) > 0 || a.y() == b.y()) continue;
      const double t = (y - a.y()) / (b.y() - a.y());
      const Eigen::Vector3d p = a + t * (b - a);
      pts.emplace_back(p.x(), p.z());
    }
    if (pts.size() >= 2) segs.push_back({pts[0], pts[1]});
  }
  return segs;
}

// Distance along `dir` from the origin to the farthest segment it crosses (0 when none).
double farthest_hit(const std::vector<Segment>& segs, const Eigen::Vector2d& dir) {
  double best = 0;
  for (const auto& [a, b] : segs) {
    const Eigen::Vector2d e = b - a;
    const double den = dir.x() * (-e.y()) - dir.y() * (-e.x());
    if (std::abs(den) < 1e-12) continue;
    // Solve t * dir = a + u * e  ->  t * dir - u * e = a.
    const double t = (a.x() * (-e.y()) - a.y() * (-e.x())) / den;
    const double u = (dir.x() * a.y() - dir.y() * a.x()) / den;
    if (u >= 0 && u <= 1 && t > best) best = t;
  }
  return best;
}

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[96];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

// The JSON by hand, to keep each row on one line and the numbers at the table's precision.
std::string generic_head_json() {
  const orthoface::sim::Head head = orthoface::sim::make_head(0);
  const double top = head.landmarks.at("forehead_top").y();
  const double bottom = head.landmarks.at("chin_bottom").y();
  const int rows = static_cast<int>(std::ceil((top - bottom) / kStepMm)) + 1;
  std::string j = "{\n  \"source\": \"gen_generic_head: the average simulated head (seed 0)\",\n";
  j += "  \"units\": \"mm, head frame\",\n";
  j += "  \"rows\": " + std::to_string(rows) + ",\n";
  j += "  \"half_rays\": " + std::to_string(kHalfRays) + ",\n";
  j += format("  \"top\": %.4f,\n  \"bottom\": %.4f,\n", top, bottom);
  j += "  \"contour_comment\": \"per row (top to bottom), per ray 0..90 degrees: x, z\",\n";
  j += "  \"contour\": [\n";
  for (int r = 0; r < rows; ++r) {
    const double y = top - (top - bottom) * r / (rows - 1);
    const auto segs = slice_segments(head.mesh, std::clamp(y, bottom + 0.05, top - 0.05));
    j += "    [";
    for (int i = 0; i < kHalfRays; ++i) {
      const double phi = M_PI / 2 * i / (kHalfRays - 1);
      const Eigen::Vector2d dir(std::sin(phi), std::cos(phi));
      const double t = farthest_hit(segs, dir);
      j += format("[%.2f, %.2f]", t * dir.x(), t * dir.y()) + (i + 1 < kHalfRays ? ", " : "");
    }
    j += r + 1 < rows ? "],\n" : "]\n";
  }
  j += "  ],\n  \"landmarks\": {\n";
  size_t n = 0;
  for (const auto& [name, p] : head.landmarks)
    j += "    \"" + name + "\": " + format("[%.3f, %.3f, %.3f]", p.x(), p.y(), p.z()) +
         (++n < head.landmarks.size() ? ",\n" : "\n");
  j += "  }\n}\n";
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: gen_generic_head OUT.json\n");
    return 2;
  }
  try {
    orthoface::io::write_text_atomically(argv[1], generic_head_json());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
