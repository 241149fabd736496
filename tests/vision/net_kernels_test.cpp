#include "vision/net_kernels.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace orthoface::vision {
namespace {

std::vector<float> random_values(size_t n, unsigned seed) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<float> v(n);
  for (float& a : v) a = u(g);
  return v;
}

// Both kernels (the vector one where this CPU has it) against the product written out, over
// the network's shapes and row counts that leave every remainder of the six-row blocks.
TEST(PointwiseProduct, BothKernelsGiveTheProductWrittenOut) {
  if (!has_vector_units()) std::cout << "this CPU has no AVX2 + FMA: the portable kernel only\n";
  struct Shape {
    int n, k, m;
  };
  for (const Shape s : {Shape{49, 256, 256}, Shape{196, 64, 128}, Shape{7, 32, 16},
                        Shape{11, 27, 32}, Shape{3, 5, 7}}) {
    const std::vector<float> x = random_values(size_t(s.n) * s.k, 1),
                             w = random_values(size_t(s.k) * s.m, 2), b = random_values(s.m, 3);
    for (bool vector_units : {false, true}) {
      std::vector<float> y(size_t(s.n) * s.m, NAN);
      pointwise_product(x.data(), w.data(), b.data(), y.data(), s.n, s.k, s.m, vector_units);
      for (int r = 0; r < s.n; ++r)
        for (int o = 0; o < s.m; ++o) {
          double want = b[o];
          for (int c = 0; c < s.k; ++c)
            want += double(x[size_t(r) * s.k + c]) * w[size_t(c) * s.m + o];
          ASSERT_NEAR(y[size_t(r) * s.m + o], want, 1e-4)
              << s.n << "x" << s.k << "x" << s.m << " vector " << vector_units;
        }
    }
  }
}

// A product large enough to be shared among threads (the network's first layer: 56 x 56 pixels,
// 27 taps, 32 outputs) gives the very same numbers as on one thread.
TEST(PointwiseProduct, SharedAmongThreadsTheProductIsTheSame) {
  const int n = 56 * 56, k = 27, m = 32;
  const std::vector<float> x = random_values(size_t(n) * k, 6), w = random_values(size_t(k) * m, 7),
                           b = random_values(m, 8);
  const int threads = cv::getNumThreads();
  for (bool vector_units : {false, true}) {
    std::vector<float> one(size_t(n) * m, NAN), many(size_t(n) * m, NAN);
    cv::setNumThreads(1);
    pointwise_product(x.data(), w.data(), b.data(), one.data(), n, k, m, vector_units);
    cv::setNumThreads(std::max(2, threads));
    pointwise_product(x.data(), w.data(), b.data(), many.data(), n, k, m, vector_units);
    for (size_t i = 0; i < one.size(); ++i) ASSERT_EQ(one[i], many[i]) << i;
    double want = b[5];  // one entry written out: row 3000, output 5
    for (int c = 0; c < k; ++c) want += double(x[size_t(3000) * k + c]) * w[size_t(c) * m + 5];
    EXPECT_NEAR(many[size_t(3000) * m + 5], want, 1e-4);
  }
  cv::setNumThreads(threads);
}

// Strides 1 and 2, with TensorFlow's 'same' padding (one pixel before) and without it (the
// last row and column then reach past the map): zero outside x either way.
TEST(DepthwiseConvolution, BothKernelsGiveTheSumWrittenOutWithZeroOutside) {
  const int h = 9, w = 7, c = 24;
  const std::vector<float> x = random_values(size_t(h) * w * c, 4), f = random_values(9 * c, 5);
  for (int stride : {1, 2})
    for (int pad : {0, 1}) {
      const int oh = (h + stride - 1) / stride, ow = (w + stride - 1) / stride;
      for (bool vector_units : {false, true}) {
        std::vector<float> y(size_t(oh) * ow * c, NAN);
        depthwise3x3(x.data(), h, w, c, f.data(), stride, pad, pad, y.data(), oh, ow, vector_units);
        for (int r = 0; r < oh; ++r)
          for (int q = 0; q < ow; ++q)
            for (int i = 0; i < c; ++i) {
              double want = 0;
              for (int dy = 0; dy < 3; ++dy)
                for (int dx = 0; dx < 3; ++dx) {
                  const int sy = r * stride + dy - pad, sx = q * stride + dx - pad;
                  if (sy >= 0 && sx >= 0 && sy < h && sx < w)
                    want += double(x[(size_t(sy) * w + sx) * c + i]) * f[(dy * 3 + dx) * c + i];
                }
              ASSERT_NEAR(y[(size_t(r) * ow + q) * c + i], want, 1e-5)
                  << "stride " << stride << " pad " << pad << " vector " << vector_units;
            }
      }
    }
}

TEST(NetKernels, BadArgumentsThrow) {
  std::vector<float> a(64, 1.0f), out(64, 0.0f);
  float* y = out.data();
  EXPECT_THROW(pointwise_product(nullptr, a.data(), a.data(), y, 2, 2, 2), std::invalid_argument);
  EXPECT_THROW(pointwise_product(a.data(), a.data(), a.data(), y, 0, 2, 2), std::invalid_argument);
  EXPECT_THROW(pointwise_product(a.data(), a.data(), a.data(), y, 2, 2, -1), std::invalid_argument);
  EXPECT_THROW(depthwise3x3(a.data(), 2, 2, 2, nullptr, 1, 1, 1, y, 2, 2), std::invalid_argument);
  EXPECT_THROW(depthwise3x3(a.data(), 2, 0, 2, a.data(), 1, 1, 1, y, 2, 2), std::invalid_argument);
  EXPECT_THROW(depthwise3x3(a.data(), 2, 2, 2, a.data(), 3, 1, 1, y, 1, 1), std::invalid_argument);
}

}  // namespace
}  // namespace orthoface::vision
