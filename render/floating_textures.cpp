#include "render/floating_textures.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace orthoface::render {
namespace {

void require(const cv::Mat& m, int type, cv::Size size, const std::string& what) {
  if (m.empty() || m.type() != type || m.size() != size)
    throw std::invalid_argument("float_textures: " + what + " must be " +
                                (type == CV_8UC3 ? "8-bit BGR" : "8-bit single-channel") +
                                " of the view's size " + std::to_string(size.width) + "x" +
                                std::to_string(size.height));
}

// Smooths a flow field and drops its sub-pixel part: where the mesh is right the two renderings
// agree and DIS still returns a few tenths of a pixel of noise, which would only blur the photo.
void settle(cv::Mat& flow) {
  cv::GaussianBlur(flow, flow, cv::Size(0, 0), 1.5);
  for (int y = 0; y < flow.rows; ++y) {
    auto* f = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const double len = std::hypot(f[x][0], f[x][1]);
      const double t = std::clamp((len - 0.5) / 1.0, 0.0, 1.0);  // 0 below 0.5 px, 1 above 1.5
      f[x] *= float(t * t * (3 - 2 * t));
    }
  }
}

// `image` sampled at x + k * flow(x) (bilinear, edges repeated).
cv::Mat warp(const cv::Mat& image, const cv::Mat& flow, double k) {
  cv::Mat map(flow.size(), CV_32FC2);
  for (int y = 0; y < flow.rows; ++y) {
    const auto* f = flow.ptr<cv::Vec2f>(y);
    auto* m = map.ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow.cols; ++x)
      m[x] = cv::Vec2f(float(x + k * f[x][0]), float(y + k * f[x][1]));
  }
  cv::Mat out;
  cv::remap(image, out, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

// Keeps `flow` (x -> x + flow(x)) only where `back` (the flow the other way) returns to x: the
// forward-backward check. Where the two photos show different things (an eye shut in one and
// open in the other, a strand of hair in one alone) no correspondence exists and the flow is
// noise; warping by it smears the feature. Full trust within 1 px of a round trip, none from 3 px;
// past a flow of 4 px the allowance grows with it (a quarter of its length: DIS's round trip over
// a 20 px move of a real eye misses by several pixels and the move is still right).
void keep_consistent(cv::Mat& flow, const cv::Mat& back) {
  const cv::Mat returned = warp(back, flow, 1.0);  // back at x + flow(x)
  cv::Mat trust(flow.size(), CV_32F);
  for (int y = 0; y < flow.rows; ++y) {
    const auto* f = flow.ptr<cv::Vec2f>(y);
    const auto* r = returned.ptr<cv::Vec2f>(y);
    auto* t = trust.ptr<float>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const double miss = std::hypot(f[x][0] + r[x][0], f[x][1] + r[x][1]) /
                          std::max(1.0, std::hypot(double(f[x][0]), double(f[x][1])) / 4);
      t[x] = float(std::clamp((3.0 - miss) / 2.0, 0.0, 1.0));
    }
  }
  cv::GaussianBlur(trust, trust, cv::Size(0, 0), 2.0);
  cv::Mat trust2;
  cv::merge(std::vector<cv::Mat>{trust, trust}, trust2);
  flow = flow.mul(trust2);
}

// Burt & Adelson 1983 ("A Multiresolution Spline With Application to Image Mosaics", ACM TOG
// 2(4), §3): each Laplacian band of `a` and `b` (CV_32FC3) mixed by the share `w` of `a`
// (CV_32F, 0..1) smoothed to that band's scale, the bands summed back. A step in brightness
// between the two photos spreads over the coarsest band's reach (2^(levels-1) px), while edges
// and texture still switch within a pixel or two, so neither a hard seam nor a ghost shows.
cv::Mat multiband(const cv::Mat& a, const cv::Mat& b, const cv::Mat& w, int levels) {
  std::vector<cv::Mat> pa{a}, pb{b}, pw{w};
  for (int l = 1; l < levels && std::min(pa.back().rows, pa.back().cols) >= 8; ++l) {
    cv::Mat da, db, dw;
    cv::pyrDown(pa.back(), da);
    cv::pyrDown(pb.back(), db);
    cv::pyrDown(pw.back(), dw);
    pa.push_back(da), pb.push_back(db), pw.push_back(dw);
  }
  auto mix = [](const cv::Mat& x, const cv::Mat& y, const cv::Mat& share) {
    cv::Mat s3;
    cv::merge(std::vector<cv::Mat>(3, share), s3);
    return cv::Mat(x.mul(s3) + y.mul(cv::Scalar::all(1.0) - s3));
  };
  const size_t top = pa.size() - 1;
  cv::Mat out = mix(pa[top], pb[top], pw[top]);
  for (size_t l = top; l-- > 0;) {
    cv::Mat up, ua, ub;
    cv::pyrUp(out, up, pa[l].size());
    cv::pyrUp(pa[l + 1], ua, pa[l].size());
    cv::pyrUp(pb[l + 1], ub, pa[l].size());
    out = up + mix(pa[l] - ua, pb[l] - ub, pw[l]);
  }
  return out;
}

}  // namespace

double float_alpha(const cv::Vec3d& to_view, const cv::Vec3d& to_front, const cv::Vec3d& to_side) {
  auto angle = [](const cv::Vec3d& a, const cv::Vec3d& b) {
    const double n = cv::norm(a) * cv::norm(b);
    if (!(n > 0) || !std::isfinite(n))
      throw std::invalid_argument("float_alpha: directions must be finite and non-zero");
    return std::acos(std::clamp(a.dot(b) / n, -1.0, 1.0));
  };
  const double to_f = angle(to_view, to_front), to_s = angle(to_view, to_side);
  return to_f + to_s > 0 ? to_f / (to_f + to_s) : 0.0;
}

FloatResult float_textures(const FloatInputs& in, const cv::Mat& base) {
  if (base.empty() || base.type() != CV_8UC3)
    throw std::invalid_argument("float_textures: the rendered view must be 8-bit BGR");
  const cv::Size size = base.size();
  for (int i = 0; i < 2; ++i) {
    const std::string name = i == 0 ? "front" : "side";
    require(in.source[i], CV_8UC3, size, name + " source image");
    require(in.available[i], CV_8U, size, name + " availability");
  }
  require(in.weights, CV_8UC3, size, "weights");
  require(in.mask, CV_8U, size, "mask");
  if (!(in.alpha >= 0 && in.alpha <= 1))
    throw std::invalid_argument("float_textures: alpha must be in 0..1, got " +
                                std::to_string(in.alpha));
  if (in.bands < 1 || in.bands > 12)
    throw std::invalid_argument("float_textures: bands must be 1..12, got " +
                                std::to_string(in.bands));
  FloatResult r;
  r.image = base.clone();
  const int margin = 16;
  cv::Rect roi = cv::boundingRect(in.mask);
  if (roi.empty()) return r;
  roi = cv::Rect(roi.x - margin, roi.y - margin, roi.width + 2 * margin, roi.height + 2 * margin) &
        cv::Rect(cv::Point(0, 0), size);

  // Each source where its photo does not see the surface takes the blend's colour, so the flow
  // finds no motion there and the warp stays inside what the photos show.
  cv::Mat src[2], grey[2];
  for (int i = 0; i < 2; ++i) {
    src[i] = base(roi).clone();
    in.source[i](roi).copyTo(src[i], in.available[i](roi));
    cv::cvtColor(src[i], grey[i], cv::COLOR_BGR2GRAY);
  }
  // DIS flow, medium preset (coarse-to-fine patch search + variational refinement): I0(x) ~
  // I1(x + f01(x)) and I1(x) ~ I0(x + f10(x)).
  cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  cv::Mat f01, f10;
  dis->calc(grey[0], grey[1], f01);
  dis->calc(grey[1], grey[0], f10);
  if (in.round_trip) {
    const cv::Mat raw01 = f01.clone();
    keep_consistent(f01, f10);
    keep_consistent(f10, raw01);
  }
  settle(f01);
  settle(f10);
  // eq. 3: a feature at p0 in I0 and p1 in I1 moves to (1 - alpha) p0 + alpha p1 in both.
  const cv::Mat w0 = warp(src[0], f10, in.alpha);
  const cv::Mat w1 = warp(src[1], f01, 1.0 - in.alpha);

  // eq. 4's blend of the two aligned images, band by band: the share of the front photo among
  // the two, the unseen fill added after.
  cv::Mat share(roi.size(), CV_32F);
  for (int y = 0; y < roi.height; ++y) {
    const auto* wt = in.weights.ptr<cv::Vec3b>(roi.y + y) + roi.x;
    auto* sh = share.ptr<float>(y);
    for (int x = 0; x < roi.width; ++x) {
      const int s = wt[x][0] + wt[x][1];
      sh[x] = s > 0 ? float(wt[x][0]) / float(s) : 0.5f;
    }
  }
  cv::Mat f0, f1;
  w0.convertTo(f0, CV_32FC3);
  w1.convertTo(f1, CV_32FC3);
  // At a source camera's own view (alpha 0 or 1) the blend is that photo, pixel for pixel: the
  // bands would carry the other photo's brightness around the few pixels it alone sees. They
  // count in full from a quarter of the way between the cameras.
  const double banded = in.bands > 1 ? std::min(1.0, 4 * in.alpha * (1 - in.alpha)) : 0.0;
  cv::Mat both = multiband(f0, f1, share, banded > 0 ? in.bands : 1);
  if (banded > 0 && banded < 1)
    cv::addWeighted(both, banded, multiband(f0, f1, share, 1), 1 - banded, 0, both);

  double shift = 0;
  for (int y = 0; y < roi.height; ++y) {
    const auto* m = in.mask.ptr<uchar>(roi.y + y) + roi.x;
    const auto* a0 = in.available[0].ptr<uchar>(roi.y + y) + roi.x;
    const auto* a1 = in.available[1].ptr<uchar>(roi.y + y) + roi.x;
    const auto* wt = in.weights.ptr<cv::Vec3b>(roi.y + y) + roi.x;
    const auto* c = both.ptr<cv::Vec3f>(y);
    const auto* f = f01.ptr<cv::Vec2f>(y);
    auto* out = r.image.ptr<cv::Vec3b>(roi.y + y) + roi.x;
    for (int x = 0; x < roi.width; ++x) {
      if (!m[x]) continue;
      if (a0[x] && a1[x]) shift += std::hypot(f[x][0], f[x][1]), ++r.overlap_pixels;
      // eq. 4: the blend's own weights, now over aligned images.
      const double s = wt[x][0] + wt[x][1] + wt[x][2];
      if (s <= 0) continue;
      for (int k = 0; k < 3; ++k)
        out[x][k] =
            cv::saturate_cast<uchar>(((wt[x][0] + wt[x][1]) * c[x][k] + wt[x][2] * in.fill[k]) / s);
    }
  }
  if (r.overlap_pixels > 0) r.mean_shift_px = shift / r.overlap_pixels;
  return r;
}

}  // namespace orthoface::render
