#include "vision/feature_filters.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <opencv2/imgproc.hpp>

#include "vision/landmarks.h"

namespace orthoface::vision {

namespace {

cv::Rect clip(const cv::Mat& m, double x0, double y0, double x1, double y1) {
  cv::Rect r(cv::Point(int(std::floor(std::min(x0, x1))), int(std::floor(std::min(y0, y1)))),
             cv::Point(int(std::ceil(std::max(x0, x1))) + 1, int(std::ceil(std::max(y0, y1))) + 1));
  return r & cv::Rect(0, 0, m.cols, m.rows);
}

// Window clipped to the part of the image the context converted.
cv::Rect clip_to(const FilterContext& c, double x0, double y0, double x1, double y1) {
  return clip(c.bgr, x0, y0, x1, y1) & c.roi;
}

Feature2d make(cv::Point2d p, double conf, const std::string& method) {
  Feature2d f;
  f.px = p;
  f.confidence = std::clamp(conf, 0.0, 1.0);
  f.method = method;
  return f;
}

// Skin colour around a small feature: the per-channel median Lab of the window's 2-px frame
// (mostly skin, and lit like the feature; the cheek sample can differ by a shading step).
cv::Vec3f frame_skin(const FilterContext& c, const cv::Rect& roi) {
  std::vector<uchar> ch[3];
  for (int r = 0; r < roi.height; ++r) {
    const cv::Vec3b* p = c.lab.ptr<cv::Vec3b>(roi.y + r) + roi.x;
    const bool edge_row = r < 2 || r >= roi.height - 2;
    for (int x = 0; x < roi.width; ++x)
      if (edge_row || x < 2 || x >= roi.width - 2)
        for (int k = 0; k < 3; ++k) ch[k].push_back(p[x][k]);
  }
  cv::Vec3f s;
  for (int k = 0; k < 3; ++k) {
    std::nth_element(ch[k].begin(), ch[k].begin() + ch[k].size() / 2, ch[k].end());
    s[k] = ch[k][ch[k].size() / 2];
  }
  return s;
}

// Binary map of pixels inside `roi` that are not skin: chroma (Lab a*, b*) farther than `tau`
// from `skin`, much darker than it, or whitish (the sclera: not darker than the skin and under
// 60 % of its saturation). Lightness alone is left out: shading on a curved face changes it by
// 50 units within an eye window while the skin's chroma stays put.
cv::Mat non_skin(const FilterContext& c, const cv::Rect& roi, cv::Vec3f skin, double tau) {
  cv::Mat m(roi.size(), CV_8U);
  const float dark = 0.55f * skin[0], tau2 = float(tau * tau);
  const float sat2 =
      0.36f * ((skin[1] - 128) * (skin[1] - 128) + (skin[2] - 128) * (skin[2] - 128));
  for (int r = 0; r < roi.height; ++r) {
    const cv::Vec3b* p = c.lab.ptr<cv::Vec3b>(roi.y + r) + roi.x;
    uchar* o = m.ptr<uchar>(r);
    for (int x = 0; x < roi.width; ++x) {
      const float da = p[x][1] - skin[1], db = p[x][2] - skin[2];
      const float a = p[x][1] - 128.f, b = p[x][2] - 128.f;
      const bool white = p[x][0] >= skin[0] && a * a + b * b < sat2;
      o[x] = (da * da + db * db > tau2 || p[x][0] < dark || white) ? 255 : 0;
    }
  }
  return m;
}

// Component of `m` containing `seed` (ROI coordinates); its pixels' bounding extremes.
struct Blob {
  bool ok = false;
  cv::Point2d left, right;  // leftmost / rightmost pixel (mean row at that column)
  int area = 0;
};
Blob blob_at(const cv::Mat& m, cv::Point seed) {
  Blob b;
  if (!cv::Rect(0, 0, m.cols, m.rows).contains(seed) || !m.at<uchar>(seed)) return b;
  cv::Mat labels;
  cv::connectedComponents(m, labels, 8, CV_32S);
  const int id = labels.at<int>(seed);
  int xmin = m.cols, xmax = -1;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      if (labels.at<int>(r, c) == id) xmin = std::min(xmin, c), xmax = std::max(xmax, c), ++b.area;
  double yl = 0, yr = 0;
  int nl = 0, nr = 0;
  for (int r = 0; r < m.rows; ++r) {
    if (labels.at<int>(r, xmin) == id) yl += r, ++nl;
    if (labels.at<int>(r, xmax) == id) yr += r, ++nr;
  }
  b.ok = true;
  b.left = {xmin - 0.5, yl / nl};
  b.right = {xmax + 0.5, yr / nr};
  return b;
}

// Darkest point of the blurred grey inside roi (image coordinates) and its contrast to the median.
cv::Point darkest(const FilterContext& c, const cv::Rect& roi, double sigma, double* contrast) {
  cv::Mat g;
  cv::GaussianBlur(c.grey(roi), g, cv::Size(), sigma, 0,
                   cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
  double lo = 0;
  cv::Point at;
  cv::minMaxLoc(g, &lo, nullptr, &at);
  std::vector<uchar> v(g.begin<uchar>(), g.end<uchar>());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  *contrast = v[v.size() / 2] - lo;
  return at + roi.tl();
}

}  // namespace

FilterContext make_filter_context(const cv::Mat& bgr, cv::Point2d at, double W,
                                  const cv::Rect& box) {
  FilterContext c;
  c.bgr = bgr;
  // Only the box (the filters' windows stay inside it) is converted; the rest of the
  // full-size grey / Lab images is left unset. A whole-image conversion dominated the time.
  c.grey.create(bgr.size(), CV_8U);
  c.lab.create(bgr.size(), CV_8UC3);
  const cv::Rect face = box & cv::Rect(0, 0, bgr.cols, bgr.rows);
  c.roi = face;
  if (face.area() > 0) {
    cv::Mat g = c.grey(face), l = c.lab(face);
    cv::cvtColor(bgr(face), g, cv::COLOR_BGR2GRAY);
    cv::cvtColor(bgr(face), l, cv::COLOR_BGR2Lab);
  }
  const double h = std::max(3.0, 0.05 * W);
  const cv::Rect roi = clip(bgr, at.x - 2.5 * h, at.y - h, at.x - 1.0 * h, at.y + h) |
                       (clip(bgr, at.x + 1.0 * h, at.y - h, at.x + 2.5 * h, at.y + h) & face);
  if (roi.area() > 0) {
    const cv::Scalar m = cv::mean(c.lab(roi));
    c.skin = cv::Vec3f(float(m[0]), float(m[1]), float(m[2]));
  }
  return c;
}

EyeFound find_eye(const FilterContext& c, double x0, double rn, double W, double H, bool il) {
  EyeFound e;
  const double s = il ? -1 : 1;
  const cv::Rect win =
      clip_to(c, x0 + s * 0.07 * W, rn - 0.03 * H, x0 + s * 0.42 * W, rn + 0.09 * H);
  if (win.area() < 16) return e;
  double contrast = 0;
  const cv::Point iris = darkest(c, win, std::max(1.0, 0.012 * W), &contrast);
  const cv::Rect band =
      clip_to(c, iris.x - 0.2 * W, iris.y - 0.045 * W, iris.x + 0.2 * W, iris.y + 0.045 * W);
  cv::Mat m = non_skin(c, band, frame_skin(c, band), 12.0);
  cv::morphologyEx(m, m, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
  const Blob b = blob_at(m, iris - band.tl());
  e.centre = cv::Point2d(iris);
  e.confidence = std::clamp(contrast / 60.0, 0.0, 1.0);
  if (!b.ok || b.right.x - b.left.x < 0.06 * W || b.right.x - b.left.x > 0.4 * W) {
    e.ok = contrast > 25;
    e.corner_image_left = e.centre - cv::Point2d(0.1 * W, 0);
    e.corner_image_right = e.centre + cv::Point2d(0.1 * W, 0);
    e.confidence *= 0.4;
    return e;
  }
  e.ok = contrast > 15;
  e.corner_image_left = b.left + cv::Point2d(band.tl());
  e.corner_image_right = b.right + cv::Point2d(band.tl());
  // The iris centre: centre of the dark blob, between the corners' rows.
  e.centre.y = 0.5 * e.centre.y + 0.25 * (e.corner_image_left.y + e.corner_image_right.y);
  return e;
}

EyeFound find_side_eye(const FilterContext& c, double xp, double row, double H, double behind) {
  EyeFound e;
  const double x0 = xp + behind * 0.015 * H, x1 = xp + behind * 0.13 * H;
  const cv::Rect win =
      clip_to(c, std::min(x0, x1), row - 0.035 * H, std::max(x0, x1), row + 0.035 * H);
  if (win.width < 6 || win.height < 4) return e;
  cv::Mat m = non_skin(c, win, frame_skin(c, win), 12.0);
  cv::morphologyEx(m, m, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(m, labels, stats, centroids, 8, CV_32S);
  // The eye: the largest component not touching the window's top or bottom (brow, hair).
  int best = -1;
  for (int i = 1; i < n; ++i) {
    const int top = stats.at<int>(i, cv::CC_STAT_TOP), h = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    if (top == 0 || top + h >= win.height || stats.at<int>(i, cv::CC_STAT_WIDTH) < 0.02 * H)
      continue;
    if (best < 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
      best = i;
  }
  if (best < 0) return e;
  const int left = stats.at<int>(best, cv::CC_STAT_LEFT),
            w = stats.at<int>(best, cv::CC_STAT_WIDTH);
  const double cy = win.y + centroids.at<double>(best, 1);
  const double front = behind > 0 ? win.x + left - 0.5 : win.x + left + w - 0.5;
  const double back = behind > 0 ? win.x + left + w - 0.5 : win.x + left - 0.5;
  // The iris: the darkest pixel of the blurred grey over the component.
  cv::Mat g;
  cv::GaussianBlur(c.grey(win), g, cv::Size(), std::max(1.0, 0.006 * H));
  double lo = 1e9;
  cv::Point at(-1, -1);
  for (int r = 0; r < win.height; ++r)
    for (int x = 0; x < win.width; ++x)
      if (labels.at<int>(r, x) == best && g.at<uchar>(r, x) < lo)
        lo = g.at<uchar>(r, x), at = {x, r};
  e.ok = true;
  e.centre = {double(win.x + at.x), cy};
  e.corner_image_left = {front, cy};
  e.corner_image_right = {back, cy};
  e.confidence =
      std::clamp(double(stats.at<int>(best, cv::CC_STAT_AREA)) / (0.002 * H * H), 0.2, 0.8);
  return e;
}

MouthFound find_mouth(const FilterContext& c, double x0, double r_lu, double r_ll, double W,
                      double H) {
  MouthFound mo;
  const cv::Rect win = clip_to(c, x0 - 0.32 * W, r_lu - 0.04 * H, x0 + 0.32 * W, r_ll + 0.04 * H);
  if (win.area() < 16) return mo;
  // Lip redness against the skin: a fixed margin first; pale real lips (a few Lab a* units
  // redder than the skin) get a second try with a threshold adapted to the window's reddest tenth.
  std::vector<float> da;
  da.reserve(win.area());
  for (int r = 0; r < win.height; ++r) {
    const cv::Vec3b* p = c.lab.ptr<cv::Vec3b>(win.y + r) + win.x;
    for (int x = 0; x < win.width; ++x) da.push_back(p[x][1] - c.skin[1]);
  }
  std::nth_element(da.begin(), da.begin() + da.size() * 9 / 10, da.end());
  const float adaptive = std::clamp(0.5f * da[da.size() * 9 / 10], 2.5f, 6.0f);
  const cv::Point seed(int(x0) - win.x, int((r_lu + r_ll) / 2) - win.y);
  Blob b;
  for (const float tau : {6.0f, adaptive}) {
    cv::Mat m(win.size(), CV_8U);
    for (int r = 0; r < win.height; ++r) {
      const cv::Vec3b* p = c.lab.ptr<cv::Vec3b>(win.y + r) + win.x;
      for (int x = 0; x < win.width; ++x)
        m.at<uchar>(r, x) = (p[x][1] - c.skin[1] > tau || p[x][0] < c.skin[0] - 35) ? 255 : 0;
    }
    cv::morphologyEx(m, m, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
    b = blob_at(m, seed);
    if (!b.ok) {  // seed missed the lips: take the component nearest the seed
      std::vector<cv::Point> nz;
      cv::findNonZero(m, nz);
      if (nz.empty()) continue;
      const auto best = std::min_element(nz.begin(), nz.end(), [&](cv::Point a, cv::Point d) {
        return cv::norm(a - seed) < cv::norm(d - seed);
      });
      b = blob_at(m, *best);
    }
    if (b.ok && b.right.x - b.left.x >= 0.15 * W) break;
  }
  const double width = b.right.x - b.left.x;
  if (!b.ok || width < 0.15 * W) return mo;
  mo.ok = true;
  mo.corner_image_left = b.left + cv::Point2d(win.tl());
  mo.corner_image_right = b.right + cv::Point2d(win.tl());
  mo.confidence = width < 0.6 * W ? 0.8 : 0.3;
  return mo;
}

NoseFound find_nose(const FilterContext& c, double x0, double r_tip, double r_sub, double W,
                    double H) {
  NoseFound n;
  if (c.roi.width < 3 || c.roi.height < 3) return n;
  const cv::Rect win = clip_to(c, x0 - 0.15 * W, r_tip, x0 + 0.15 * W, r_sub + 0.03 * H);
  if (win.area() < 16) return n;
  cv::Mat g;
  cv::GaussianBlur(c.grey(win), g, cv::Size(), 1.0, 0,
                   cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
  double pos[2] = {0, 0}, val[2] = {1e9, 1e9};
  double py[2] = {0, 0};
  for (int r = 0; r < g.rows; ++r)
    for (int x = 0; x < g.cols; ++x) {
      const int side = (x + win.x) < x0 ? 0 : 1;
      if (g.at<uchar>(r, x) < val[side])
        val[side] = g.at<uchar>(r, x), pos[side] = x + win.x, py[side] = r + win.y;
    }
  const double d0 = x0 - pos[0], d1 = pos[1] - x0;
  const bool found =
      val[0] < c.skin[0] * 0.6 && val[1] < c.skin[0] * 0.6 && d0 > 0.01 * W && d1 > 0.01 * W;
  const double d = found ? 0.5 * (d0 + d1) : 0.06 * W;
  const double row_rule =
      found ? 0.5 * (py[0] + py[1]) - 0.25 * (r_sub - r_tip) : r_tip + 0.68 * (r_sub - r_tip);
  // Wing edge: strongest horizontal grey change outward of the nostril along a row, 0.4 d to
  // 1.5 d beyond that side's own nostril (a turned head shifts the two nostrils unevenly from
  // x0, and a fixed range from x0 then misses the far wing); nullopt without a clear edge.
  auto nostril = [&](int side) { return found ? pos[side] : x0 + (side ? d : -d); };
  auto wing_edge = [&](int side, double y_row) -> std::optional<double> {
    const double s = side == 0 ? -1 : 1;
    const double base = nostril(side);
    const int y = std::clamp(int(std::lround(y_row)), c.roi.y + 1, c.roi.br().y - 2);
    std::optional<double> at;
    double best = 0;
    for (double t = 0.4 * d; t <= 1.5 * d; t += 0.5) {
      const int x = std::clamp(int(std::lround(base + s * t)), c.roi.x + 1, c.roi.br().x - 2);
      const double gx = std::abs(double(c.grey.at<uchar>(y, x + 1)) - c.grey.at<uchar>(y, x - 1));
      if (gx > best && gx > 6) best = gx, at = base + s * t;
    }
    return at;
  };
  // The alare is the wing's most lateral point: of the rows from the nostrils up to the row
  // rule above, the one where the two wing edges lie farthest apart.
  double row = row_rule, ax[2] = {0, 0};
  for (int side = 0; side < 2; ++side)
    ax[side] = wing_edge(side, row).value_or(nostril(side) + (side ? 0.9 : -0.9) * d);
  if (found) {
    double widest = -1;
    for (double y = 0.5 * (py[0] + py[1]); y >= row_rule - 0.5; y -= 1.0) {
      const auto l = wing_edge(0, y), r = wing_edge(1, y);
      if (l && r && *r - *l > widest) widest = *r - *l, row = y, ax[0] = *l, ax[1] = *r;
    }
  }
  n.ok = true;  // without nostrils the wing edges (or the position model) still place them
  n.alar_image_left = {ax[0], row};
  n.alar_image_right = {ax[1], row};
  n.confidence = found ? 0.6 : 0.15;
  return n;
}

void add_eye_features(const EyeFound& a, const EyeFound& b, FrontFeatures& out) {
  // Image-left eye = subject's right eye; its inner corner is the one nearer the image centre.
  if (a.ok) {
    out.features["eye_right_center"] = make(a.centre, a.confidence, "filter-dark-blob");
    out.features["eye_right_outer"] = make(a.corner_image_left, a.confidence, "filter-component");
    out.features["eye_right_inner"] = make(a.corner_image_right, a.confidence, "filter-component");
  }
  if (b.ok) {
    out.features["eye_left_center"] = make(b.centre, b.confidence, "filter-dark-blob");
    out.features["eye_left_inner"] = make(b.corner_image_left, b.confidence, "filter-component");
    out.features["eye_left_outer"] = make(b.corner_image_right, b.confidence, "filter-component");
  }
}

void add_brow_features(const FilterContext& c, const EyeFound& a, const EyeFound& b, double W,
                       double H, FrontFeatures& out) {
  for (int side = 0; side < 2; ++side) {
    const EyeFound& e = side == 0 ? a : b;
    if (!e.ok) continue;
    const std::string name = side == 0 ? "brow_right_" : "brow_left_";
    const cv::Rect win = clip_to(c, e.centre.x - 0.17 * W, e.centre.y - 0.11 * H,
                                 e.centre.x + 0.17 * W, e.centre.y - 0.025 * H);
    if (win.area() < 16) continue;
    cv::Mat m;
    cv::compare(c.grey(win), c.skin[0] * 0.62, m, cv::CMP_LT);
    cv::morphologyEx(m, m, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
    cv::Mat labels, stats, cents;
    const int k = cv::connectedComponentsWithStats(m, labels, stats, cents, 8, CV_32S);
    int best = -1;
    for (int i = 1; i < k; ++i)
      if (best < 0 || stats.at<int>(i, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA))
        best = i;
    if (best < 0 || stats.at<int>(best, cv::CC_STAT_WIDTH) < 0.08 * W) continue;
    const auto mean_row = [&](int col) {
      double s = 0;
      int n = 0;
      for (int r = 0; r < labels.rows; ++r)
        if (labels.at<int>(r, col) == best) s += r, ++n;
      return n ? s / n + win.y : -1.0;
    };
    const int x0 = stats.at<int>(best, cv::CC_STAT_LEFT),
              x1 = x0 + stats.at<int>(best, cv::CC_STAT_WIDTH) - 1;
    const int xc = std::clamp(int(std::lround(e.centre.x)) - win.x, x0, x1);
    const cv::Point2d pl(x0 + win.x, mean_row(x0)), pr(x1 + win.x, mean_row(x1)),
        pc(xc + win.x, mean_row(xc));
    const double conf = 0.7 * e.confidence + 0.3;
    out.features[name + "center"] = make(pc, conf, "filter-dark-band");
    out.features[name + "inner"] = make(side == 0 ? pr : pl, conf, "filter-dark-band");
    out.features[name + "outer"] = make(side == 0 ? pl : pr, conf, "filter-dark-band");
  }
}

void add_nose_mouth_features(const NoseFound& n, const MouthFound& m, FrontFeatures& out) {
  if (n.ok) {
    out.features["alar_right"] = make(n.alar_image_left, n.confidence, "filter-nostril+edge");
    out.features["alar_left"] = make(n.alar_image_right, n.confidence, "filter-nostril+edge");
  }
  if (m.ok) {
    out.features["mouth_right"] = make(m.corner_image_left, m.confidence, "filter-lip-colour");
    out.features["mouth_left"] = make(m.corner_image_right, m.confidence, "filter-lip-colour");
  }
}

void mirror_missing(FrontFeatures& out) {
  for (std::string_view name : kLandmarkNames) {
    if (name.find("ear_") == 0) continue;  // ears are seen from the side camera only
    const std::string other = mirrored_name(name);
    if (other == name || out.features.count(std::string(name)) || !out.features.count(other))
      continue;
    Feature2d f = out.features[other];
    f.px = mirror_point(out.centre, f.px);
    f.confidence *= 0.6;
    f.method = "mirrored";
    f.mirrored = true;
    out.features[std::string(name)] = f;
    out.warnings.push_back("front view: " + std::string(name) + " not found, mirrored from " +
                           other);
  }
}

}  // namespace orthoface::vision
