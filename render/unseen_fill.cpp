#include "render/unseen_fill.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace orthoface::render {

namespace {

constexpr int kSeenBelow = 26;  // unseen share x255 under which a pixel gives its colour
constexpr int kMarginPx = 32;   // the seen surface looked at around the holes' bounding box

void check_plane(const cv::Mat& m, const cv::Size& size, const char* what) {
  if (m.type() != CV_8U || m.size() != size)
    throw std::invalid_argument(std::string("unseen fill: ") + what +
                                " must be 8-bit single-channel of the image's size");
}

}  // namespace

int fill_unseen(cv::Mat& image, const cv::Mat& unseen, const cv::Mat& mask, cv::Vec3b fill) {
  if (image.empty() || image.type() != CV_8UC3)
    throw std::invalid_argument("unseen fill: the image must be a non-empty 8-bit BGR image");
  check_plane(unseen, image.size(), "the unseen shares");
  check_plane(mask, image.size(), "the surface mask");
  const cv::Mat surface = mask > 0;
  const cv::Mat holes = (unseen > 0) & surface;
  if (cv::countNonZero(holes) == 0) return 0;
  // Only the holes' neighbourhood is interpolated: the rest of the view keeps its colours.
  const cv::Rect all(0, 0, image.cols, image.rows);
  cv::Rect box = cv::boundingRect(holes);
  box = cv::Rect(box.x - kMarginPx, box.y - kMarginPx, box.width + 2 * kMarginPx,
                 box.height + 2 * kMarginPx) &
        all;
  cv::Mat seen = (unseen(box) < kSeenBelow) & surface(box);
  if (cv::countNonZero(seen) == 0) {
    box = all;
    seen = (unseen < kSeenBelow) & surface;
    if (cv::countNonZero(seen) == 0) return 0;
  }
  // Pull: colours weighted by seen (premultiplied) and the weights, averaged level by level until
  // every pixel of a level has some seen surface under it.
  std::vector<cv::Mat> colour(1), weight(1);
  image(box).convertTo(colour[0], CV_32FC3);
  seen.convertTo(weight[0], CV_32F, 1.0 / 255);
  {
    cv::Mat w3;
    cv::merge(std::vector<cv::Mat>(3, weight[0]), w3);
    colour[0] = colour[0].mul(w3);
  }
  while (std::min(colour.back().cols, colour.back().rows) > 1) {
    double least;
    cv::minMaxLoc(weight.back(), &least);
    if (least > 0) break;
    cv::Mat c, w;
    cv::pyrDown(colour.back(), c);
    cv::pyrDown(weight.back(), w);
    colour.push_back(c), weight.push_back(w);
  }
  // Push: each level's own average where enough seen surface lies under it, blended into the
  // coarser level's result where less does.
  auto average = [](const cv::Mat& c, const cv::Mat& w, const cv::Mat& coarser) {
    cv::Mat out(c.size(), CV_32FC3);
    for (int y = 0; y < c.rows; ++y) {
      const auto* cp = c.ptr<cv::Vec3f>(y);
      const float* wp = w.ptr<float>(y);
      const auto* up = coarser.empty() ? nullptr : coarser.ptr<cv::Vec3f>(y);
      auto* op = out.ptr<cv::Vec3f>(y);
      for (int x = 0; x < c.cols; ++x) {
        const float own = std::min(1.0f, 4.0f * wp[x]);  // a quarter seen is enough
        const cv::Vec3f mine = wp[x] > 1e-6f ? cp[x] / wp[x] : cv::Vec3f();
        op[x] = up ? own * mine + (1.0f - own) * up[x] : mine;
      }
    }
    return out;
  };
  cv::Mat filled = average(colour.back(), weight.back(), {});
  for (int k = int(colour.size()) - 2; k >= 0; --k) {
    cv::Mat up;
    cv::pyrUp(filled, up, colour[k].size());
    filled = average(colour[k], weight[k], up);
  }
  // The fill's share of each hole pixel takes the interpolated colour instead.
  int changed = 0;
  const cv::Vec3f flat(fill[0], fill[1], fill[2]);
  for (int y = 0; y < box.height; ++y) {
    auto* ip = image.ptr<cv::Vec3b>(box.y + y) + box.x;
    const uchar* up = unseen.ptr<uchar>(box.y + y) + box.x;
    const uchar* mp = mask.ptr<uchar>(box.y + y) + box.x;
    const auto* fp = filled.ptr<cv::Vec3f>(y);
    for (int x = 0; x < box.width; ++x) {
      if (up[x] == 0 || mp[x] == 0) continue;
      const float share = up[x] / 255.0f;
      for (int k = 0; k < 3; ++k)
        ip[x][k] = cv::saturate_cast<uchar>(ip[x][k] + share * (fp[x][k] - flat[k]));
      ++changed;
    }
  }
  return changed;
}

}  // namespace orthoface::render
