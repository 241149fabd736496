#include "vision/face_descriptor.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <opencv2/core.hpp>

#include "vision/net_kernels.h"
#include "vision/tfjs_weights.h"

namespace orthoface::vision {
namespace {

constexpr int kInput = 150;  // the network's input side
const char* const kModelFile = "face_recognition_model.bin";
const char* const kManifestFile = "face_recognition_model-weights_manifest.json";

// A feature map, height x width x channels, channels fastest.
struct Map {
  int h = 0, w = 0, c = 0;
  std::vector<float> v;
  Map() = default;
  Map(int h_, int w_, int c_) : h(h_), w(w_), c(c_), v(size_t(h_) * w_ * c_, 0.0f) {}
  float* at(int y, int x) { return v.data() + (size_t(y) * w + x) * c; }
  const float* at(int y, int x) const { return v.data() + (size_t(y) * w + x) * c; }
};

// A convolution with its per-channel scale folded in: y = (conv(x, f) + bias) * s + t =
// conv(x, f * s) + (bias * s + t).
struct Conv {
  int k = 0, in = 0, out = 0;
  std::vector<float> filters;  // [k][k][in][out]
  std::vector<float> bias;     // [out]
};

// k x k convolution with `stride`, `pad` zero pixels before the first row / column, output
// oh x ow: the patches laid out as rows, then one matrix product with the filters.
Map convolve(const Map& x, const Conv& f, int stride, int pad, int oh, int ow, bool relu) {
  const int taps = f.k * f.k * x.c;
  std::vector<float> patches(size_t(oh) * ow * taps, 0.0f);
  for (int r = 0; r < oh; ++r)
    for (int q = 0; q < ow; ++q) {
      float* o = patches.data() + (size_t(r) * ow + q) * taps;
      for (int dy = 0; dy < f.k; ++dy)
        for (int dx = 0; dx < f.k; ++dx) {
          const int sy = r * stride + dy - pad, sx = q * stride + dx - pad;
          if (sy >= 0 && sx >= 0 && sy < x.h && sx < x.w)
            std::copy_n(x.at(sy, sx), x.c, o + (dy * f.k + dx) * x.c);
        }
    }
  Map y(oh, ow, f.out);
  pointwise_product(patches.data(), f.filters.data(), f.bias.data(), y.v.data(), oh * ow, taps,
                    f.out);
  if (relu)
    for (float& a : y.v) a = std::max(a, 0.0f);
  return y;
}

// TensorFlow's 'same' 3x3 convolution, stride 1.
Map same3(const Map& x, const Conv& f, bool relu) { return convolve(x, f, 1, 1, x.h, x.w, relu); }
// TensorFlow's 'valid' convolution with stride 2.
Map valid2(const Map& x, const Conv& f, bool relu) {
  return convolve(x, f, 2, 0, (x.h - f.k) / 2 + 1, (x.w - f.k) / 2 + 1, relu);
}

// 'valid' pooling of size x size windows with `stride`: the maximum or the mean.
Map pool(const Map& x, int size, int stride, bool max) {
  Map y((x.h - size) / stride + 1, (x.w - size) / stride + 1, x.c);
  for (int r = 0; r < y.h; ++r)
    for (int q = 0; q < y.w; ++q) {
      float* o = y.at(r, q);
      for (int k = 0; k < x.c; ++k) o[k] = max ? -INFINITY : 0.0f;
      for (int dy = 0; dy < size; ++dy)
        for (int dx = 0; dx < size; ++dx) {
          const float* a = x.at(r * stride + dy, q * stride + dx);
          for (int k = 0; k < x.c; ++k) o[k] = max ? std::max(o[k], a[k]) : o[k] + a[k];
        }
      if (!max)
        for (int k = 0; k < x.c; ++k) o[k] /= float(size * size);
    }
  return y;
}

}  // namespace

// FaceRecognitionNet (face-api.js): a 7x7 / 2 convolution and a 3x3 / 2 max pool, then residual
// blocks of two 3x3 convolutions (each followed by a per-channel scale; ReLU after the first and
// after the sum); a down-sampling block's first convolution has stride 2 and its shortcut is a
// 2x2 average pool, zero-padded in channels, with the convolutions' map zero-padded by a row and a
// column where it came out smaller. Then the mean over the last map and a 256 -> 128 product.
struct FaceDescriber::Net {
  std::map<std::string, Conv> conv;
  std::vector<float> fc;  // [256][128]

  Map residual(const Map& x, const std::string& name) const {
    Map e = same3(same3(x, conv.at(name + "/conv1"), true), conv.at(name + "/conv2"), false);
    for (size_t k = 0; k < e.v.size(); ++k) e.v[k] = std::max(e.v[k] + x.v[k], 0.0f);
    return e;
  }

  Map down(const Map& x, const std::string& name) const {
    const Map e = same3(valid2(x, conv.at(name + "/conv1"), true), conv.at(name + "/conv2"), false);
    const Map r = pool(x, 2, 2, false);
    Map y(r.h, r.w, e.c);
    for (int row = 0; row < y.h; ++row)
      for (int q = 0; q < y.w; ++q) {
        float* o = y.at(row, q);
        const float* s = r.at(row, q);
        for (int k = 0; k < r.c; ++k) o[k] = s[k];
        if (row < e.h && q < e.w) {
          const float* a = e.at(row, q);
          for (int k = 0; k < e.c; ++k) o[k] += a[k];
        }
        for (int k = 0; k < e.c; ++k) o[k] = std::max(o[k], 0.0f);
      }
    return y;
  }

  FaceDescriptor run(const Map& input) const {
    Map x = pool(valid2(input, conv.at("conv32_down"), true), 3, 2, true);
    for (const char* b : {"conv32_1", "conv32_2", "conv32_3"}) x = residual(x, b);
    x = down(x, "conv64_down");
    for (const char* b : {"conv64_1", "conv64_2", "conv64_3"}) x = residual(x, b);
    x = down(x, "conv128_down");
    for (const char* b : {"conv128_1", "conv128_2"}) x = residual(x, b);
    x = down(x, "conv256_down");
    for (const char* b : {"conv256_1", "conv256_2"}) x = residual(x, b);
    x = down(x, "conv256_down_out");
    std::vector<double> mean(x.c, 0.0);
    for (int r = 0; r < x.h; ++r)
      for (int q = 0; q < x.w; ++q)
        for (int k = 0; k < x.c; ++k) mean[k] += x.at(r, q)[k] / double(x.h * x.w);
    FaceDescriptor out{};
    for (int o = 0; o < 128; ++o) {
      double s = 0;
      for (int k = 0; k < x.c; ++k) s += mean[k] * fc[size_t(k) * 128 + o];
      out[o] = float(s);
    }
    return out;
  }
};

double descriptor_distance(const FaceDescriptor& a, const FaceDescriptor& b) {
  double s = 0;
  for (size_t k = 0; k < a.size(); ++k) s += double(a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(s);
}

cv::Rect face_descriptor_crop(const std::array<cv::Point2d, 68>& p, cv::Size image) {
  const auto centre = [&](int from, int to) {
    cv::Point2d c(0, 0);
    for (int k = from; k < to; ++k) c += p[k];
    return c / double(to - from);
  };
  const cv::Point2d left = centre(36, 42), right = centre(42, 48), mouth = centre(48, 68);
  const double side = std::floor((cv::norm(mouth - left) + cv::norm(mouth - right)) / 2 / 0.45);
  const cv::Point2d mid = (left + right + mouth) / 3.0;
  if (!(side >= 1) || !std::isfinite(mid.x) || !std::isfinite(mid.y)) return {};
  const double x = std::floor(std::max(0.0, mid.x - 0.5 * side));
  const double y = std::floor(std::max(0.0, mid.y - 0.43 * side));
  if (x >= image.width || y >= image.height) return {};
  return cv::Rect(int(x), int(y), int(std::min(side, image.width - x)),
                  int(std::min(side, image.height - y)));
}

FaceDescriber::FaceDescriber(const std::string& model_dir) : net_(std::make_unique<Net>()) {
  std::map<std::string, NetWeight> w =
      read_tfjs_weights(model_dir, kManifestFile, kModelFile, "face descriptor");
  const std::string where = model_dir + "/" + kManifestFile;
  const auto take = [&](const std::string& name, const std::vector<int>& shape) {
    const auto it = w.find(name);
    if (it == w.end() || it->second.shape != shape)
      throw std::runtime_error("face descriptor: " + where + ": weight " + name +
                               " missing or of another shape");
    return it->second.v;
  };
  const auto add_conv = [&](const std::string& name, int k, int in, int out) {
    Conv c;
    c.k = k, c.in = in, c.out = out;
    c.filters = take(name + "/conv/filters", {k, k, in, out});
    const std::vector<float> b = take(name + "/conv/bias", {out});
    const std::vector<float> s = take(name + "/scale/weights", {out});
    const std::vector<float> t = take(name + "/scale/biases", {out});
    for (size_t i = 0; i < c.filters.size(); ++i) c.filters[i] *= s[i % out];
    c.bias.resize(out);
    for (int o = 0; o < out; ++o) c.bias[o] = b[o] * s[o] + t[o];
    net_->conv[name] = std::move(c);
  };
  add_conv("conv32_down", 7, 3, 32);
  int in = 32;
  for (const auto& [block, out, count] :
       {std::tuple{"conv32", 32, 3}, std::tuple{"conv64", 64, 3}, std::tuple{"conv128", 128, 2},
        std::tuple{"conv256", 256, 2}}) {
    const std::string b = block;
    if (out != 32) {
      add_conv(b + "_down/conv1", 3, in, out);
      add_conv(b + "_down/conv2", 3, out, out);
    }
    for (int i = 1; i <= count; ++i) {
      add_conv(b + "_" + std::to_string(i) + "/conv1", 3, out, out);
      add_conv(b + "_" + std::to_string(i) + "/conv2", 3, out, out);
    }
    in = out;
  }
  add_conv("conv256_down_out/conv1", 3, 256, 256);
  add_conv("conv256_down_out/conv2", 3, 256, 256);
  net_->fc = take("fc", {256, 128});
}

FaceDescriber::~FaceDescriber() = default;
FaceDescriber::FaceDescriber(FaceDescriber&&) noexcept = default;
FaceDescriber& FaceDescriber::operator=(FaceDescriber&&) noexcept = default;

FaceDescriptor FaceDescriber::describe_crop(const cv::Mat& bgr) const {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("face descriptor: the crop must be a non-empty 8-bit BGR image");
  // Black padding to a square, the larger share after the crop (face-api.js's padToSquare),
  // then bilinear resizing without half-pixel centres (TensorFlow's resizeBilinear default).
  const int n = std::abs(bgr.rows - bgr.cols), after = (n + 1) / 2, before = n - after;
  cv::Mat square;
  if (bgr.rows > bgr.cols)
    cv::copyMakeBorder(bgr, square, 0, 0, before, after, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  else
    cv::copyMakeBorder(bgr, square, before, after, 0, 0, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  const float mean_rgb[3] = {122.782f, 117.001f, 104.298f};
  const double scale = double(square.rows) / kInput;
  Map input(kInput, kInput, 3);
  for (int r = 0; r < kInput; ++r) {
    const double sy = r * scale;
    const int y0 = std::min(int(sy), square.rows - 1), y1 = std::min(y0 + 1, square.rows - 1);
    const double fy = sy - y0;
    for (int q = 0; q < kInput; ++q) {
      const double sx = q * scale;
      const int x0 = std::min(int(sx), square.cols - 1), x1 = std::min(x0 + 1, square.cols - 1);
      const double fx = sx - x0;
      const cv::Vec3b &a = square.at<cv::Vec3b>(y0, x0), &b = square.at<cv::Vec3b>(y0, x1),
                      &c = square.at<cv::Vec3b>(y1, x0), &d = square.at<cv::Vec3b>(y1, x1);
      float* o = input.at(r, q);
      for (int k = 0; k < 3; ++k) {
        const int ch = 2 - k;  // RGB from BGR
        const double top = a[ch] + (b[ch] - a[ch]) * fx, bottom = c[ch] + (d[ch] - c[ch]) * fx;
        o[k] = (float(top + (bottom - top) * fy) - mean_rgb[k]) / 255.0f;
      }
    }
  }
  return net_->run(input);
}

FaceDescriptor FaceDescriber::describe(const cv::Mat& bgr,
                                       const std::array<cv::Point2d, 68>& points) const {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("face descriptor: the image must be a non-empty 8-bit BGR image");
  for (const cv::Point2d& p : points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throw std::invalid_argument("face descriptor: a landmark is not finite");
  const cv::Rect crop = face_descriptor_crop(points, bgr.size());
  if (crop.empty())
    throw std::invalid_argument("face descriptor: the face's crop lies outside the image");
  return describe_crop(bgr(crop));
}

const FaceDescriber* shared_describer() {
  static const std::optional<FaceDescriber> net = []() -> std::optional<FaceDescriber> {
    try {
      return FaceDescriber(default_model_dir());
    } catch (const std::runtime_error&) {
      return std::nullopt;
    }
  }();
  return net ? &*net : nullptr;
}

}  // namespace orthoface::vision
