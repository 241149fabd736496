#include "judge/head_region.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::judge {

cv::Mat head_region(const cv::Mat& photo, const cv::Rect& face_box,
                    const Landmarks68* face_points) {
  if (photo.empty() || photo.type() != CV_8UC3)
    throw std::invalid_argument("head_region: the photo must be 8-bit BGR and not empty");
  const cv::Rect frame(0, 0, photo.cols, photo.rows);
  if (face_box.width < 4 || face_box.height < 4 || (face_box & frame) != face_box)
    throw std::invalid_argument("head_region: the face box is not inside the photo");
  // A face point is on the photo or near it (a face cut by the frame's edge): one further off
  // is not a face of this photo.
  if (face_points)
    for (const cv::Point2d& p : *face_points)
      if (!(std::abs(p.x - 0.5 * photo.cols) <= 1.5 * photo.cols &&
            std::abs(p.y - 0.5 * photo.rows) <= 1.5 * photo.rows))
        throw std::invalid_argument(
            "head_region: a face point lies far outside the photo or "
            "is not a number");
  const double k = std::min(1.0, 480.0 / photo.cols);
  cv::Mat small;
  cv::resize(photo, small, {}, k, k, cv::INTER_AREA);
  const cv::Rect small_frame(0, 0, small.cols, small.rows);
  auto scaled = [&](double x, double y, double w, double h) {
    return cv::Rect(int(std::lround(x * k)), int(std::lround(y * k)), int(std::lround(w * k)),
                    int(std::lround(h * k))) &
           small_frame;
  };
  const double w = face_box.width, h = face_box.height;
  const double cx = face_box.x + 0.5 * w;
  // Surely not head: anything farther than a head's reach from the face (1.4 face widths beside
  // the box, 1.1 heights above it, 0.9 below) and the frame's top and side edges.
  const cv::Rect reach = scaled(face_box.x - 1.4 * w, face_box.y - 1.1 * h, 3.8 * w, 3.0 * h);
  cv::Mat mask(small.size(), CV_8U, cv::Scalar(cv::GC_BGD));
  mask(reach).setTo(cv::GC_PR_BGD);
  // Probably head: an ellipse round the face and the hair above and behind it, wide enough
  // that the hair's colours teach the head's model, not the background's. With dlib's points
  // it is set by the face and its turn (the nose tip's place between the outer eye corners):
  // the back of a turned head reaches about 1.3 eye distances behind the jaw, its nose side
  // little beyond the nose tip; the crown 0.8 brow-to-chin heights above the brows.
  cv::Point2d centre(cx, face_box.y + 0.4 * h), axes(1.15 * w, 1.1 * h);
  if (face_points) {
    const Landmarks68& p = *face_points;
    double x0 = p[0].x, x1 = p[0].x, brow = p[17].y;
    for (const cv::Point2d& q : p) x0 = std::min(x0, q.x), x1 = std::max(x1, q.x);
    for (int i = 17; i < 27; ++i) brow = std::min(brow, p[size_t(i)].y);
    const double e = std::max(1.0, std::abs(p[45].x - p[36].x));
    const double between = nose_between_eyes(p), s = std::isnan(between) ? 0.5 : between;
    const double f = std::clamp(std::abs(s - 0.5) / 0.4, 0.0, 1.0);
    const bool nose_right = (s > 0.5) == (p[45].x > p[36].x);
    const double near = e * (0.35 * (1 - f) + 0.15 * f), back = e * (0.35 * (1 - f) + 1.3 * f);
    const double left = x0 - (nose_right ? back : near), right = x1 + (nose_right ? near : back);
    const double tall = std::max(1.0, p[8].y - brow), top = brow - 0.8 * tall,
                 bottom = p[8].y + 0.3 * tall;
    centre = {0.5 * (left + right), 0.5 * (top + bottom)};
    axes = {0.5 * (right - left), 0.5 * (bottom - top)};
  }
  cv::ellipse(mask, cv::Point(int(std::lround(centre.x * k)), int(std::lround(centre.y * k))),
              cv::Size(std::max(1, int(std::lround(axes.x * k))),
                       std::max(1, int(std::lround(axes.y * k)))),
              0, 0, 360, cv::GC_PR_FGD, cv::FILLED);
  const int edge = std::max(2, small.cols / 100);
  mask.rowRange(0, edge).setTo(cv::GC_BGD);
  mask.colRange(0, edge).setTo(cv::GC_BGD);
  mask.colRange(small.cols - edge, small.cols).setTo(cv::GC_BGD);
  // Surely head: the face's inner features (brows, eyes, nose, mouth) when given, else the face
  // box's middle.
  cv::Point seed;
  if (face_points) {
    std::vector<cv::Point> pts;
    for (size_t i = 17; i < face_points->size(); ++i) {
      const cv::Point2d& p = (*face_points)[i];
      pts.emplace_back(int(std::lround(p.x * k)), int(std::lround(p.y * k)));
    }
    std::vector<cv::Point> hull;
    cv::convexHull(pts, hull);
    cv::fillConvexPoly(mask, hull, cv::GC_FGD);
    const cv::Moments m = cv::moments(hull);
    seed = m.m00 > 0 ? cv::Point(int(m.m10 / m.m00), int(m.m01 / m.m00)) : pts[0];
  } else {
    const cv::Rect sure = scaled(face_box.x + 0.2 * w, face_box.y + 0.2 * h, 0.6 * w, 0.6 * h);
    mask(sure).setTo(cv::GC_FGD);
    seed = {sure.x + sure.width / 2, sure.y + sure.height / 2};
  }
  seed.x = std::clamp(seed.x, 0, small.cols - 1), seed.y = std::clamp(seed.y, 0, small.rows - 1);
  cv::Mat bgd, fgd;
  // A fixed k-means seed (the thread's cv::theRNG()): the region depends on the photo alone and
  // the caller's random state is left as it was.
  cv::RNG& rng = cv::theRNG();
  const uint64 caller_state = rng.state;
  rng.state = 0xffffffff;  // cv::RNG's default state, a fresh thread's
  cv::grabCut(small, mask, cv::Rect(), bgd, fgd, 5, cv::GC_INIT_WITH_MASK);
  rng.state = caller_state;
  cv::Mat head = (mask == cv::GC_FGD) | (mask == cv::GC_PR_FGD);
  // The part that holds the face.
  cv::Mat labels;
  cv::connectedComponents(head, labels, 8, CV_32S);
  const int face_label = labels.at<int>(seed.y, seed.x);
  head = face_label > 0 ? labels == face_label : cv::Mat::zeros(small.size(), CV_8U);
  cv::Mat full;
  cv::resize(head, full, photo.size(), 0, 0, cv::INTER_LINEAR);
  return full > 127;
}

double head_iou(const cv::Mat& view_mask, const cv::Mat& view_to_real, const cv::Mat& real_mask,
                double max_row) {
  for (const cv::Mat* m : {&view_mask, &real_mask})
    if (m->empty() || m->type() != CV_8UC1)
      throw std::invalid_argument("head_iou: the masks must be 8-bit single-channel, not empty");
  if (view_to_real.rows != 2 || view_to_real.cols != 3)
    throw std::invalid_argument("head_iou: the transform must be 2x3");
  cv::Mat carried;
  cv::warpAffine(view_mask, carried, view_to_real, real_mask.size(), cv::INTER_NEAREST,
                 cv::BORDER_CONSTANT, 0);
  const int rows = std::clamp(int(std::ceil(max_row)), 0, real_mask.rows);
  const cv::Mat a = carried.rowRange(0, rows) > 0, b = real_mask.rowRange(0, rows) > 0;
  const int uni = cv::countNonZero(a | b);
  return uni == 0 ? 0.0 : double(cv::countNonZero(a & b)) / uni;
}

double black_fraction(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U)
    throw std::invalid_argument("black_fraction: the image must be 8-bit and not empty");
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  cv::Mat lit = channels[0].clone();  // non-zero where any channel is
  for (size_t c = 1; c < channels.size(); ++c) lit |= channels[c];
  return double(image.total() - cv::countNonZero(lit)) / double(image.total());
}

}  // namespace orthoface::judge
