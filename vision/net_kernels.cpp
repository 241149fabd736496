#include "vision/net_kernels.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define ORTHOFACE_X86_KERNEL 1
#endif

namespace orthoface::vision {
namespace {

// Products of fewer multiplications than this run on the calling thread alone: below it,
// waking a second thread costs more than it saves.
constexpr double kParallelMultiplies = 2e6;

using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Eigen's product: SSE2 on any x86-64 (Debian's baseline), whatever this CPU has beyond it.
void portable(const float* x, const float* w, const float* bias, float* y, int n, int k, int m) {
  const Eigen::Map<const RowMajor> xm(x, n, k);
  const Eigen::Map<const RowMajor> wm(w, k, m);
  const Eigen::Map<const Eigen::RowVectorXf> b(bias, m);
  Eigen::Map<RowMajor> ym(y, n, m);
  ym.noalias() = xm * wm;
  ym.rowwise() += b;
}

void depthwise_portable(const float* x, int h, int w, int c, const float* f, int stride, int pad_y,
                        int pad_x, float* y, int oh, int ow) {
  for (int r = 0; r < oh; ++r)
    for (int q = 0; q < ow; ++q) {
      float* o = y + (size_t(r) * ow + q) * c;
      std::fill_n(o, c, 0.0f);
      for (int dy = 0; dy < 3; ++dy)
        for (int dx = 0; dx < 3; ++dx) {
          const int sy = r * stride + dy - pad_y, sx = q * stride + dx - pad_x;
          if (sy < 0 || sx < 0 || sy >= h || sx >= w) continue;
          const float* in = x + (size_t(sy) * w + sx) * c;
          const float* k = f + size_t(dy * 3 + dx) * c;
          for (int i = 0; i < c; ++i) o[i] += in[i] * k[i];
        }
    }
}

#ifdef ORTHOFACE_X86_KERNEL
// R rows of x against 16 columns of w, the 2R accumulators in registers: each step loads two
// vectors of w and broadcasts R values of x (R = 6: 12 accumulators + 3 operands of the 16 ymm
// registers).
template <int R>
__attribute__((target("avx2,fma"))) inline void rows_by_16(const float* x, const float* w,
                                                           const float* bias, float* y, int k,
                                                           int m) {
  __m256 acc[R][2];
  for (int r = 0; r < R; ++r)
    acc[r][0] = _mm256_loadu_ps(bias), acc[r][1] = _mm256_loadu_ps(bias + 8);
  for (int c = 0; c < k; ++c) {
    const __m256 w0 = _mm256_loadu_ps(w + size_t(c) * m),
                 w1 = _mm256_loadu_ps(w + size_t(c) * m + 8);
    for (int r = 0; r < R; ++r) {
      const __m256 v = _mm256_broadcast_ss(x + size_t(r) * k + c);
      acc[r][0] = _mm256_fmadd_ps(v, w0, acc[r][0]);
      acc[r][1] = _mm256_fmadd_ps(v, w1, acc[r][1]);
    }
  }
  for (int r = 0; r < R; ++r) {
    _mm256_storeu_ps(y + size_t(r) * m, acc[r][0]);
    _mm256_storeu_ps(y + size_t(r) * m + 8, acc[r][1]);
  }
}

// Column panels of 16 outer, rows inner: the panel of w (k x 16, at most 16 KB) stays in the
// first-level cache while every row passes it.
__attribute__((target("avx2,fma"))) void vectorised(const float* x, const float* w,
                                                    const float* bias, float* y, int n, int k,
                                                    int m) {
  for (int o = 0; o < m; o += 16) {
    int p = 0;
    for (; p + 6 <= n; p += 6)
      rows_by_16<6>(x + size_t(p) * k, w + o, bias + o, y + size_t(p) * m + o, k, m);
    // The last n % 6 rows, by the kernel of their count.
    using Rows = void (*)(const float*, const float*, const float*, float*, int, int);
    static constexpr Rows kRest[6] = {nullptr,       rows_by_16<1>, rows_by_16<2>,
                                      rows_by_16<3>, rows_by_16<4>, rows_by_16<5>};
    if (n > p) kRest[n - p](x + size_t(p) * k, w + o, bias + o, y + size_t(p) * m + o, k, m);
  }
}

// Eight channels at a time, the nine taps summed in a register.
__attribute__((target("avx2,fma"))) void depthwise_vectorised(const float* x, int h, int w, int c,
                                                              const float* f, int stride, int pad_y,
                                                              int pad_x, float* y, int oh, int ow) {
  const float* in[9];
  const float* k[9];
  for (int r = 0; r < oh; ++r)
    for (int q = 0; q < ow; ++q) {
      int taps = 0;
      for (int dy = 0; dy < 3; ++dy)
        for (int dx = 0; dx < 3; ++dx) {
          const int sy = r * stride + dy - pad_y, sx = q * stride + dx - pad_x;
          if (sy < 0 || sx < 0 || sy >= h || sx >= w) continue;
          in[taps] = x + (size_t(sy) * w + sx) * c, k[taps++] = f + size_t(dy * 3 + dx) * c;
        }
      float* o = y + (size_t(r) * ow + q) * c;
      for (int i = 0; i < c; i += 8) {
        __m256 acc = _mm256_setzero_ps();
        for (int t = 0; t < taps; ++t)
          acc = _mm256_fmadd_ps(_mm256_loadu_ps(in[t] + i), _mm256_loadu_ps(k[t] + i), acc);
        _mm256_storeu_ps(o + i, acc);
      }
    }
}
#endif

}  // namespace

bool has_vector_units() {
#ifdef ORTHOFACE_X86_KERNEL
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

void pointwise_product(const float* x, const float* w, const float* bias, float* y, int n, int k,
                       int m, bool vector_units) {
  if (!x || !w || !bias || !y) throw std::invalid_argument("pointwise product: a null matrix");
  if (n < 1 || k < 1 || m < 1)
    throw std::invalid_argument("pointwise product: every size must be at least 1");
  const auto rows = [&](int r0, int r1) {
    const float* xr = x + size_t(r0) * k;
    float* yr = y + size_t(r0) * m;
#ifdef ORTHOFACE_X86_KERNEL
    if (vector_units && m % 16 == 0 && has_vector_units())
      return vectorised(xr, w, bias, yr, r1 - r0, k, m);
#endif
    portable(xr, w, bias, yr, r1 - r0, k, m);
  };
  // A large product's rows are shared among OpenCV's threads: each row is summed in the same
  // order whichever thread takes it, so the result is the same as on one thread.
  if (double(n) * k * m < kParallelMultiplies) return rows(0, n);
  cv::parallel_for_(
      cv::Range(0, n), [&](const cv::Range& r) { rows(r.start, r.end); }, 4);
}

void depthwise3x3(const float* x, int h, int w, int c, const float* filters, int stride, int pad_y,
                  int pad_x, float* y, int oh, int ow, bool vector_units) {
  if (!x || !filters || !y) throw std::invalid_argument("depthwise convolution: a null map");
  if (h < 1 || w < 1 || c < 1 || oh < 1 || ow < 1)
    throw std::invalid_argument("depthwise convolution: every size must be at least 1");
  if (stride < 1 || stride > 2)
    throw std::invalid_argument("depthwise convolution: the stride must be 1 or 2, got " +
                                std::to_string(stride));
#ifdef ORTHOFACE_X86_KERNEL
  if (vector_units && c % 8 == 0 && has_vector_units())
    return depthwise_vectorised(x, h, w, c, filters, stride, pad_y, pad_x, y, oh, ow);
#endif
  depthwise_portable(x, h, w, c, filters, stride, pad_y, pad_x, y, oh, ow);
}

}  // namespace orthoface::vision
