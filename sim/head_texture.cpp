// The skin texture of a simulated head: what a photo of the face shows (skin tone with
// low-frequency variation and fine noise, hair, brows, eyes, lips, nostrils, ears).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "sim/head_surface.h"

namespace orthoface::sim::detail {

namespace {

using Rgb = Eigen::Vector3d;

std::uint32_t hash3(int x, int y, int z, std::uint32_t seed) {
  std::uint32_t h = seed ^ (static_cast<std::uint32_t>(x) * 0x8da6b343u) ^
                    (static_cast<std::uint32_t>(y) * 0xd8163841u) ^
                    (static_cast<std::uint32_t>(z) * 0xcb1ab31fu);
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return h;
}

// Value noise in [-1, 1], smooth, lattice spacing `cell` mm.
double noise3(const Eigen::Vector3d& p, double cell, std::uint32_t seed) {
  const Eigen::Vector3d q = p / cell;
  const int x0 = static_cast<int>(std::floor(q.x())), y0 = static_cast<int>(std::floor(q.y())),
            z0 = static_cast<int>(std::floor(q.z()));
  auto fade = [](double t) { return t * t * (3 - 2 * t); };
  const double fx = fade(q.x() - x0), fy = fade(q.y() - y0), fz = fade(q.z() - z0);
  double acc = 0;
  for (int k = 0; k < 8; ++k) {
    const int dx = k & 1, dy = (k >> 1) & 1, dz = (k >> 2) & 1;
    const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
    acc += w * (hash3(x0 + dx, y0 + dy, z0 + dz, seed) / 4294967295.0);
  }
  return 2 * acc - 1;
}

Rgb mix(const Rgb& a, const Rgb& b, double t) { return a + std::clamp(t, 0.0, 1.0) * (b - a); }

// Soft inside-ness of a signed distance d (negative inside), edge width e mm.
double inside(double d, double e = 0.35) { return smoothstep(e, -e, d); }

// What varies slowly over the surface, sampled on a coarse (u, t) grid and interpolated.
struct Sample {
  Eigen::Vector3d q = Eigen::Vector3d::Zero();     // surface point
  Eigen::Vector3d ear{10, 0, 0};                   // HeadSurface::ear_coords
  Eigen::Vector3d tint = Eigen::Vector3d::Ones();  // skin colour factor
  double ear_w = 0, hair_noise = 0;
  Sample operator*(double w) const { return {q * w, ear * w, tint * w, ear_w * w, hair_noise * w}; }
  Sample operator+(const Sample& o) const {
    return {q + o.q, ear + o.ear, tint + o.tint, ear_w + o.ear_w, hair_noise + o.hair_noise};
  }
};

struct Column {
  double theta, cos_theta, hairline;
};

struct Painter {
  const HeadSurface& s;
  const HeadAnchors& a;
  const HeadParams& p;
  Rgb skin, hair, brow, lip;
  std::uint32_t seed;

  explicit Painter(const HeadSurface& surface)
      : s(surface), a(surface.anchors()), p(surface.params()) {
    const Rgb light(0.96, 0.80, 0.70), medium(0.80, 0.60, 0.46), dark(0.40, 0.26, 0.18);
    skin = p.skin_tone < 0.5 ? mix(light, medium, 2 * p.skin_tone)
                             : mix(medium, dark, 2 * p.skin_tone - 1);
    const double r = p.skin_redness - 0.5;
    skin = skin.cwiseProduct(Rgb(1 + 0.07 * r, 1 - 0.02 * r, 1 - 0.07 * r));
    const Rgb blond(0.78, 0.62, 0.38), brown(0.33, 0.21, 0.12), black(0.06, 0.05, 0.05);
    hair = p.hair_darkness < 0.5 ? mix(blond, brown, 2 * p.hair_darkness)
                                 : mix(brown, black, 2 * p.hair_darkness - 1);
    brow = mix(hair, Rgb(0.12, 0.08, 0.06), 0.35);
    lip = mix(skin, skin.cwiseProduct(Rgb(0.84, 0.52, 0.52)) + Rgb(0.06, 0, 0.01), 0.8);
    seed = static_cast<std::uint32_t>(p.head_width * 1000 + p.nose_length * 7777 +
                                      p.skin_tone * 99991 + p.eye_spacing * 313);
  }

  // Hairline height at azimuth theta: forehead, temples, sideburns, above the ears, nape.
  double hairline(double theta) const {
    const double t = std::abs(theta);
    const double ear_top = a.y_ear_c + a.ear_ry;
    const double knots_t[] = {0.0, 0.6, 1.0, 1.2, 1.36, 1.5, 2.0, 2.4, std::numbers::pi};
    const double knots_y[] = {a.y_hair,     a.y_hair - 4,    a.y_hair - 12,
                              a.y_brow + 6, a.y_tragus + 6,  ear_top + 4,
                              ear_top + 6,  a.y_tragus - 18, a.y_tip - 22};
    for (int k = 0; k < 8; ++k)
      if (t <= knots_t[k + 1]) {
        const double f = smoothstep(knots_t[k], knots_t[k + 1], t);
        return knots_y[k] + f * (knots_y[k + 1] - knots_y[k]);
      }
    return knots_y[8];
  }

  // Slowly varying skin colour factor at q: mottling and rosy cheeks (sampled on the grid).
  Rgb skin_tint(const Eigen::Vector3d& q) const {
    const double shade = 1 + 0.05 * noise3(q, 35, seed) + 0.03 * noise3(q, 9, seed + 1);
    Rgb c = Rgb::Constant(shade);
    for (double side : {-1.0, 1.0}) {
      const double d2 = std::pow(q.x() - side * (std::abs(a.x_eye_left) + 8), 2) / 400 +
                        std::pow(q.y() - (a.y_tip - 4), 2) / 300;
      if (q.z() > 0) c += std::exp(-d2) * 0.05 * Rgb(1.0, -0.4, -0.4);
    }
    return c;
  }

  Rgb eye(Rgb c, double x, double y, int side) const {
    const double xe = side > 0 ? a.x_eye_left : a.x_eye_right;
    const double ye = side > 0 ? a.y_eye_left : a.y_eye_right;
    const double hw = p.eye_width / 2, sx = (x - xe) / hw;
    if (std::abs(sx) > 1.25 || std::abs(y - ye) > 12) return c;
    const double k = std::max(0.0, 1 - sx * sx);
    const double yu = ye + 0.18 * p.eye_width * std::pow(k, 0.75);
    const double yl = ye - 0.13 * p.eye_width * std::pow(k, 0.85);
    c *= 1 - 0.12 * inside(std::abs(y - (yu + 4.5)) - 1.2, 1.0);  // lid crease
    const double open = inside(std::abs(sx) - 1, 0.04) * inside(y - yu) * inside(yl - y);
    const double r = std::hypot(x - xe, y - ye), ri = 0.2 * p.eye_width;
    Rgb inner = mix(Rgb(0.93, 0.91, 0.88), Rgb(0.80, 0.70, 0.68), std::pow(std::abs(sx), 4));
    const double streak = 0.15 * std::sin(std::atan2(y - ye, x - xe) * 23);
    const Rgb iris = p.iris_rgb * (0.75 + 0.35 * r / ri + streak);
    inner =
        mix(inner, mix(iris, Rgb(0.1, 0.08, 0.07), smoothstep(0.8, 1.0, r / ri)), inside(r - ri));
    inner = mix(inner, Rgb(0.03, 0.03, 0.03), inside(r - 0.42 * ri));
    c = mix(c, inner, open);
    // Lash line along the upper lid, a thin darker line along the lower one.
    const double lid = inside(std::abs(sx) - 1.04, 0.05);
    c = mix(c, Rgb(0.10, 0.08, 0.07), lid * inside(std::abs(y - (yu + 0.5)) - 0.6, 0.3));
    c *= 1 - 0.25 * lid * inside(std::abs(y - (yl - 0.3)) - 0.4, 0.3);
    return c;
  }

  Rgb brows(Rgb c, double x, double y, double strand) const {
    const int side = x >= 0 ? 1 : -1;
    const Eigen::Vector3d b0 = brow_point(s, side, 0), b1 = brow_point(s, side, 1);
    const double sb = (x - b0.x()) / (b1.x() - b0.x());
    if (sb < -0.1 || sb > 1.1) return c;
    const Eigen::Vector3d b = brow_point(s, side, std::clamp(sb, 0.0, 1.0));
    const double end = std::max(-sb, sb - 1) * (b1.x() - b0.x()) * side;
    const double w = inside(std::abs(y - b.y()) - b.z() / 2, 0.6) * inside(end, 0.8);
    return mix(c, brow, w * (0.8 + 0.2 * strand));
  }

  Rgb mouth(Rgb c, double x, double y) const {
    const double xm = x - a.x_mid, hm = p.mouth_width / 2, F = p.lip_fullness;
    if (std::abs(xm) > hm + 2 || std::abs(y - a.y_mouth) > 14) return c;
    const double k = std::max(0.0, 1 - std::pow(xm / hm, 2));
    const double bow = 1.2 * std::exp(-std::pow(xm / 3.0, 2));  // Cupid's bow dip
    const double top = a.y_mouth + (7.0 * F * std::pow(k, 0.5) - bow * std::sqrt(k));
    const double bottom = a.y_mouth - 9.0 * F * std::pow(k, 0.6);
    const double in =
        inside(y - top, 0.4) * inside(bottom - y, 0.5) * inside(std::abs(xm) - hm, 0.3);
    c = mix(c, lip * (0.95 + 0.08 * (y < a.y_mouth)), in);
    const double line = inside(std::abs(y - a.y_mouth) - 0.6 * std::sqrt(k) - 0.25, 0.35) *
                        inside(std::abs(xm) - hm, 0.3);
    return mix(c, Rgb(0.22, 0.10, 0.10), line);
  }

  Rgb nose(Rgb c, double x, double y) const {
    const double xm = x - a.x_mid, nw = p.nose_width;
    for (double side : {-1.0, 1.0}) {
      const double dx = (xm - side * (nw / 2 - 9.5)) / 3.3, dy = (y - (a.y_sub + 2.6)) / 1.9;
      c = mix(c, Rgb(0.22, 0.12, 0.10), inside(std::hypot(dx, dy) - 1, 0.3));
      // Alar crease around the nostril wing.
      const double ax = (xm - side * (nw / 2 - 7)) / 7.5, ay = (y - (a.y_sub + 5)) / 6.5;
      const double d = std::hypot(ax * 7.5 / 7.0, ay);
      if (side * xm > nw / 2 - 7) c *= 1 - 0.22 * inside(std::abs(d - 1) - 0.08, 0.06);
    }
    return c;
  }

  Rgb ear(Rgb c, const Eigen::Vector3d& e) const {
    c *= 1 - 0.3 * inside(std::abs(e[0] - 1) - 0.04, 0.03);  // outline shadow
    c *= 1 -
         0.3 * inside(std::hypot((e[1] - 0.25) / 0.45, (e[2] + 0.1) / 0.45) - 1, 0.15);  // concha
    c *= 1 - 0.12 * inside(std::abs(e[0] - 0.68) - 0.05, 0.04);  // helix fold
    return c;
  }

  // Colour at surface point q (y exact) with the grid-interpolated sample.
  // Colour at surface point q (y exact) in column `col` (azimuth, cos, hairline precomputed).
  Rgb color(const Column& col, const Eigen::Vector3d& q, const Sample& g, double fine,
            double strand) const {
    const double y = q.y();
    Rgb c = skin.cwiseProduct(g.tint) * (1 + fine);
    const double hl = col.hairline + g.hair_noise;
    const double h = inside(hl - y, 1.0) * (1 - smoothstep(0.1, 0.4, g.ear_w));
    if (h > 0) c = mix(c, hair * (1 + 0.15 * strand + 0.5 * fine), h);
    if (g.ear_w > 0.01) c = ear(c, g.ear);
    if (q.z() > 20 && col.cos_theta > 0.3 && y < a.y_brow + 16 && y > a.y_mouth - 16) {
      c = brows(c, q.x(), y, strand);
      c = eye(c, q.x(), y, q.x() >= 0 ? 1 : -1);
      c = mouth(c, q.x(), y);
      c = nose(c, q.x(), y);
    }
    return c.cwiseMax(0).cwiseMin(1);
  }
};

// Per-texel noise in [-1, 1] for a column / row index (hair strands, skin grain).
double texel_noise(int k, std::uint32_t seed) { return hash3(k, 7, 3, seed) / 2147483647.5 - 1; }

std::vector<Sample> sample_grid(const HeadSurface& surface, const HeadParametrization& param,
                                const Painter& painter, int g) {
  std::vector<Sample> grid((g + 1) * (g + 1));
  for (int r = 0; r <= g; ++r) {
    const double y = param.y(static_cast<double>(r) / g);
    for (int c = 0; c <= g; ++c) {
      const double theta = HeadParametrization::theta(static_cast<double>(c) / g);
      Sample& s = grid[r * (g + 1) + c];
      s.q = surface.point(theta, y);
      if (std::abs(std::sin(theta)) > 0.5) {
        s.ear = surface.ear_coords(theta, y);
        s.ear_w = surface.ear_weight(theta, y);
      }
      s.tint = painter.skin_tint(s.q);
      s.hair_noise = 0.9 * noise3(s.q, 6, painter.seed + 3);
    }
  }
  return grid;
}

}  // namespace

cv::Mat head_texture(const HeadSurface& surface, const HeadParametrization& param, int size) {
  // Slowly varying quantities come from a coarse (u, t) grid, bilinearly interpolated per
  // texel: evaluating the analytic surface for every texel would take seconds.
  const int g = std::min(size, 160);
  const Painter painter(surface);
  const std::vector<Sample> grid = sample_grid(surface, param, painter, g);
  // Hair strands run vertically (noise per column, smoothed); brow hairs too, roughly.
  std::vector<double> strands(size);
  std::vector<Column> cols(size);
  for (int c = 0; c < size; ++c) {
    const double th = HeadParametrization::theta((c + 0.5) / size);
    cols[c] = {th, std::cos(th), painter.hairline(th)};
  }
  for (int c = 0; c < size; ++c)
    strands[c] = 0.5 * texel_noise(c, painter.seed) + 0.25 * texel_noise(c - 1, painter.seed) +
                 0.25 * texel_noise(c + 1, painter.seed);
  cv::Mat tex(size, size, CV_8UC3);
  for (int r = 0; r < size; ++r) {
    const double t = (r + 0.5) / size, y = param.y(t);
    const double fr = t * g;
    const int r0 = std::min(static_cast<int>(fr), g - 1);
    const double wr = fr - r0;
    auto* row = tex.ptr<cv::Vec3b>(r);
    for (int c = 0; c < size; ++c) {
      const double u = (c + 0.5) / size, fc = u * g;
      const int c0 = std::min(static_cast<int>(fc), g - 1);
      const double wc = fc - c0;
      const int k = r0 * (g + 1) + c0;
      const Sample s = (grid[k] * (1 - wc) + grid[k + 1] * wc) * (1 - wr) +
                       (grid[k + g + 1] * (1 - wc) + grid[k + g + 2] * wc) * wr;
      const double fine = 0.025 * texel_noise(r * size + c, painter.seed + 5);
      const Rgb rgb =
          painter.color(cols[c], Eigen::Vector3d(s.q.x(), y, s.q.z()), s, fine, strands[c]);
      row[c] =
          cv::Vec3b(static_cast<uchar>(255 * rgb[2] + 0.5), static_cast<uchar>(255 * rgb[1] + 0.5),
                    static_cast<uchar>(255 * rgb[0] + 0.5));
    }
  }
  return tex;
}

}  // namespace orthoface::sim::detail
