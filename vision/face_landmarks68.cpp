#include "vision/face_landmarks68.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "vision/haar_init.h"
#include "vision/net_kernels.h"
#include "vision/tfjs_weights.h"

namespace orthoface::vision {
namespace {

constexpr int kInput = 112;  // the network's input side
// The square crop around the points: kCropScale x the points' larger extent, centred
// kCropLift x their height above their box's centre.
// Chosen on the 26 FRMDB front photos against dlib's points (scale 1.0-1.8, lift -0.05-0.15):
// mean error 0.041 of the outer-eye distance at 1.4 / -0.05 (0.046 at 1.2 / 0.05).
constexpr double kCropScale = 1.4, kCropLift = -0.05;
const char* const kModelFile = "face_landmark_68_model.bin";
const char* const kManifestFile = "face_landmark_68_model-weights_manifest.json";

// The storage of feature maps, kept per thread: a pass makes the same maps in the same sizes
// every time, and fresh ones (up to 400 KB, beyond the allocator's reuse) cost a page fault every
// 4 KB and the kernel's zeroing, about half a pass's time. At most 32 buffers a thread are kept
// (a pass makes fewer; the largest is 400 KB).
std::vector<std::vector<float>>& spare_storage() {
  thread_local std::vector<std::vector<float>> spare;
  return spare;
}
std::vector<float> take_storage(size_t n) {
  std::vector<std::vector<float>>& spare = spare_storage();
  auto best = spare.end();
  for (auto it = spare.begin(); it != spare.end(); ++it)
    if (it->capacity() >= n && (best == spare.end() || it->capacity() < best->capacity()))
      best = it;
  std::vector<float> v;
  if (best != spare.end()) v.swap(*best), spare.erase(best);
  v.assign(n, 0.0f);
  return v;
}
void give_storage(std::vector<float>&& v) {
  std::vector<std::vector<float>>& spare = spare_storage();
  if (v.capacity() > 0 && spare.size() < 32) spare.push_back(std::move(v));
}

// A feature map, height x width x channels, channels fastest.
struct Map {
  int h = 0, w = 0, c = 0;
  std::vector<float> v;
  Map() = default;
  Map(int h_, int w_, int c_) : h(h_), w(w_), c(c_), v(take_storage(size_t(h_) * w_ * c_)) {}
  Map(const Map& o) : h(o.h), w(o.w), c(o.c), v(take_storage(o.v.size())) {
    std::copy(o.v.begin(), o.v.end(), v.begin());
  }
  Map(Map&& o) noexcept = default;
  Map& operator=(Map o) noexcept {  // the old storage goes back with `o`
    std::swap(h, o.h), std::swap(w, o.w), std::swap(c, o.c), v.swap(o.v);
    return *this;
  }
  ~Map() { give_storage(std::move(v)); }
  float* at(int y, int x) { return v.data() + (size_t(y) * w + x) * c; }
  const float* at(int y, int x) const { return v.data() + (size_t(y) * w + x) * c; }
};

using Tensor = NetWeight;

// TensorFlow's 'same' padding: output ceil(n / stride), the odd pixel of padding at the end.
int same_out(int n, int stride) { return (n + stride - 1) / stride; }
int same_pad_begin(int n, int stride, int k) {
  return std::max((same_out(n, stride) - 1) * stride + k - n, 0) / 2;
}

// 3x3 convolution over all input channels, filters [3][3][in][out] (the first layer): the 3x3
// patches laid out as rows (zero outside x), then one matrix product with the filters, which are
// already a (9 in) x out matrix.
Map conv3x3(const Map& x, const Tensor& f, const Tensor& bias, int stride) {
  const int out_c = f.shape[3], taps = 9 * x.c;
  Map patches(same_out(x.h, stride), same_out(x.w, stride), taps);
  const int py = same_pad_begin(x.h, stride, 3), px = same_pad_begin(x.w, stride, 3);
  for (int r = 0; r < patches.h; ++r)
    for (int c = 0; c < patches.w; ++c) {
      float* o = patches.at(r, c);
      for (int dy = 0; dy < 3; ++dy)
        for (int dx = 0; dx < 3; ++dx) {
          const int sy = r * stride + dy - py, sx = c * stride + dx - px;
          if (sy >= 0 && sx >= 0 && sy < x.h && sx < x.w)
            std::copy_n(x.at(sy, sx), x.c, o + (dy * 3 + dx) * x.c);
        }
    }
  Map y(patches.h, patches.w, out_c);
  pointwise_product(patches.v.data(), f.v.data(), bias.v.data(), y.v.data(), patches.h * patches.w,
                    taps, out_c);
  return y;
}

// Depthwise 3x3 (filters [3][3][c][1]) with `stride`, then pointwise (filters [1][1][c][out])
// and the bias: TensorFlow's separableConv2d.
Map separable(const Map& x, const Tensor& depthwise, const Tensor& pointwise, const Tensor& bias,
              int stride) {
  Map d(same_out(x.h, stride), same_out(x.w, stride), x.c);
  depthwise3x3(x.v.data(), x.h, x.w, x.c, depthwise.v.data(), stride,
               same_pad_begin(x.h, stride, 3), same_pad_begin(x.w, stride, 3), d.v.data(), d.h,
               d.w);
  // The pointwise step is one matrix product, (pixels x c) (c x out) + bias.
  const int out_c = pointwise.shape[3];
  Map y(d.h, d.w, out_c);
  pointwise_product(d.v.data(), pointwise.v.data(), bias.v.data(), y.v.data(), d.h * d.w, x.c,
                    out_c);
  return y;
}

void relu(Map& x) {
  for (float& a : x.v) a = std::max(a, 0.0f);
}

// acc += x.
void add(Map& acc, const Map& x) {
  for (size_t k = 0; k < acc.v.size(); ++k) acc.v[k] += x.v[k];
}

// max(x, 0) as a new map.
Map relu_of(const Map& x) {
  Map y(x.h, x.w, x.c);
  for (size_t k = 0; k < x.v.size(); ++k) y.v[k] = std::max(x.v[k], 0.0f);
  return y;
}

}  // namespace

// FaceLandmark68Net (face-api.js): four dense blocks, each a strided first convolution and three
// separable convolutions whose inputs are the sums of all earlier outputs of the block, then a
// 7x7 average pool and a fully connected layer to 68 (x, y) in 0..1 of the crop.
struct FaceLandmarker68::Net {
  std::map<std::string, Tensor> w;

  const Tensor& t(const std::string& name) const {
    const auto it = w.find(name);
    if (it == w.end()) throw std::runtime_error("face landmarks: the model has no weight " + name);
    return it->second;
  }

  Map block(const Map& x, const std::string& b, bool first) const {
    auto sep = [&](const Map& in, int k, int stride) {
      const std::string p = b + "/conv" + std::to_string(k) + "/";
      return separable(in, t(p + "depthwise_filter"), t(p + "pointwise_filter"), t(p + "bias"),
                       stride);
    };
    Map out1 = first ? conv3x3(x, t(b + "/conv0/filters"), t(b + "/conv0/bias"), 2) : sep(x, 0, 2);
    relu(out1);
    // The inputs of the block's later convolutions are the running sum of its outputs (added in
    // the order they came, as the model's sums), each through a ReLU.
    Map acc = out1;
    add(acc, sep(out1, 1, 1));
    add(acc, sep(relu_of(acc), 2, 1));
    add(acc, sep(relu_of(acc), 3, 1));
    relu(acc);
    return acc;
  }

  std::array<float, 136> run(const Map& input) const {
    Map x = block(input, "dense0", true);
    for (const char* b : {"dense1", "dense2", "dense3"}) x = block(x, b, false);
    std::vector<float> pooled(x.c, 0.0f);  // 7x7 average pool, valid: the whole 7x7 map
    for (int r = 0; r < x.h; ++r)
      for (int c = 0; c < x.w; ++c)
        for (int k = 0; k < x.c; ++k) pooled[k] += x.at(r, c)[k] / float(x.h * x.w);
    const Tensor& fw = t("fc/weights");
    const Tensor& fb = t("fc/bias");
    std::array<float, 136> out{};
    for (int o = 0; o < 136; ++o) {
      double s = fb.v[o];
      for (int k = 0; k < x.c; ++k) s += pooled[k] * fw.v[size_t(k) * 136 + o];
      out[o] = float(s);
    }
    return out;
  }
};

std::string default_model_dir() {
  if (const char* env = std::getenv("ORTHOFACE_MODELS"); env && *env) return env;
  if (std::filesystem::exists(std::filesystem::path(ORTHOFACE_MODEL_DIR) / kManifestFile))
    return ORTHOFACE_MODEL_DIR;
  return ORTHOFACE_INSTALLED_MODEL_DIR;
}

FaceLandmarker68::FaceLandmarker68(const std::string& model_dir) : net_(std::make_unique<Net>()) {
  net_->w = read_tfjs_weights(model_dir, kManifestFile, kModelFile, "face landmarks");
  const std::string manifest_path = (std::filesystem::path(model_dir) / kManifestFile).string();
  const auto shape_is = [&](const std::string& name, std::vector<int> shape) {
    const auto it = net_->w.find(name);
    if (it == net_->w.end() || it->second.shape != shape)
      throw std::runtime_error("face landmarks: " + manifest_path + ": weight " + name +
                               " missing or of another shape");
  };
  shape_is("dense0/conv0/filters", {3, 3, 3, 32});
  int c = 32;
  for (int b = 1; b < 4; ++b, c *= 2)
    shape_is("dense" + std::to_string(b) + "/conv0/pointwise_filter", {1, 1, c, 2 * c});
  shape_is("fc/weights", {256, 136});
}

FaceLandmarker68::~FaceLandmarker68() = default;
FaceLandmarker68::FaceLandmarker68(FaceLandmarker68&&) noexcept = default;
FaceLandmarker68& FaceLandmarker68::operator=(FaceLandmarker68&&) noexcept = default;

std::array<cv::Point2d, 68> FaceLandmarker68::in_crop(const cv::Mat& bgr,
                                                      const cv::Rect2d& crop) const {
  if (bgr.empty()) throw std::invalid_argument("face landmarks: the image is empty");
  if (bgr.depth() != CV_8U || (bgr.channels() != 3 && bgr.channels() != 1))
    throw std::invalid_argument("face landmarks: the image must be 8-bit BGR or grey");
  if (!(crop.width >= 4 && crop.height >= 4) || !std::isfinite(crop.x) || !std::isfinite(crop.y))
    throw std::invalid_argument("face landmarks: the face crop is empty");
  // The crop, scaled to 112 x 112, zero outside the image (the network's training padding).
  // Only the part of the image the crop covers (and the blur's and the interpolation's reach
  // around it) is blurred and sampled.
  const double s = kInput / crop.width;
  // Shrinking more than twofold: average before sampling, as a canvas resize does.
  const double sigma = s < 0.5 ? 0.5 / s * 0.6 : 0.0;
  const int reach = 2 + int(std::ceil(4 * sigma));
  const cv::Rect roi =
      cv::Rect(
          cv::Point(int(std::floor(crop.x)) - reach, int(std::floor(crop.y)) - reach),
          cv::Point(int(std::ceil(crop.br().x)) + reach, int(std::ceil(crop.br().y)) + reach)) &
      cv::Rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat small(kInput, kInput, CV_8UC3, cv::Scalar(0, 0, 0));
  if (!roi.empty()) {
    cv::Mat src = bgr(roi);
    if (bgr.channels() == 1) cv::cvtColor(src, src, cv::COLOR_GRAY2BGR);
    if (sigma > 0) {
      cv::Mat blurred;
      cv::GaussianBlur(src, blurred, cv::Size(), sigma);
      src = blurred;
    }
    const cv::Matx23d a(s, 0, (roi.x - crop.x) * s, 0, kInput / crop.height,
                        (roi.y - crop.y) * kInput / crop.height);
    cv::warpAffine(src, small, a, small.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                   cv::Scalar(0, 0, 0));
  }
  Map input(kInput, kInput, 3);
  const float mean_rgb[3] = {122.782f, 117.001f, 104.298f};
  for (int r = 0; r < kInput; ++r)
    for (int c = 0; c < kInput; ++c) {
      const cv::Vec3b p = small.at<cv::Vec3b>(r, c);
      float* o = input.at(r, c);
      for (int k = 0; k < 3; ++k) o[k] = (float(p[2 - k]) - mean_rgb[k]) / 255.0f;  // RGB
    }
  const std::array<float, 136> out = net_->run(input);
  std::array<cv::Point2d, 68> points;
  for (int k = 0; k < 68; ++k)
    points[k] = {crop.x + out[2 * k] * crop.width, crop.y + out[2 * k + 1] * crop.height};
  return points;
}

const FaceLandmarker68* shared_landmarker() {
  static const std::optional<FaceLandmarker68> net = []() -> std::optional<FaceLandmarker68> {
    try {
      return FaceLandmarker68(default_model_dir());
    } catch (const std::runtime_error&) {
      return std::nullopt;
    }
  }();
  return net ? &*net : nullptr;
}

// Refinement stops once the points move less than this between two crops (mean, pixels).
constexpr double kConvergedPx = 0.5;

cv::Rect2d crop_from_points(const std::array<cv::Point2d, 68>& p) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const cv::Point2d& q : p)
    x0 = std::min(x0, q.x), x1 = std::max(x1, q.x), y0 = std::min(y0, q.y), y1 = std::max(y1, q.y);
  const double side = kCropScale * std::max(x1 - x0, y1 - y0);
  const cv::Point2d centre((x0 + x1) / 2, (y0 + y1) / 2 - kCropLift * (y1 - y0));
  return {centre.x - side / 2, centre.y - side / 2, side, side};
}

std::optional<FaceLandmarks68> FaceLandmarker68::detect(const cv::Mat& bgr,
                                                        const std::string& cascade_dir,
                                                        int iterations) const {
  if (bgr.empty()) throw std::invalid_argument("face landmarks: the image is empty");
  const std::optional<cv::Rect> face = haar_face(bgr, cascade_dir, false);
  if (!face) return std::nullopt;
  return detect_in(bgr, cv::Rect2d(*face), iterations);
}

FaceLandmarks68 FaceLandmarker68::detect_in(const cv::Mat& bgr, const cv::Rect2d& first_crop,
                                            int iterations) const {
  FaceLandmarks68 out;
  out.crop = first_crop;
  out.points = in_crop(bgr, out.crop);
  out.movement_px = INFINITY;
  return refine(bgr, out, iterations);
}

FaceLandmarks68 FaceLandmarker68::refine(const cv::Mat& bgr, FaceLandmarks68 out,
                                         int iterations) const {
  if (iterations < 0)
    throw std::invalid_argument("face landmarks: refinement iterations must be >= 0, got " +
                                std::to_string(iterations));
  if (out.movement_px < kConvergedPx) return out;
  for (int i = 0; i < iterations; ++i) {
    const cv::Rect2d next = crop_from_points(out.points);
    const std::array<cv::Point2d, 68> p = in_crop(bgr, next);
    double moved = 0;
    for (int k = 0; k < 68; ++k) moved += cv::norm(p[k] - out.points[k]) / 68;
    out.points = p, out.crop = next, out.movement_px = moved;
    if (moved < kConvergedPx) break;
  }
  return out;
}

}  // namespace orthoface::vision
