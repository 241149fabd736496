#pragma once
// The landmark network's two costly steps, depthwise 3x3 and pointwise (1x1) convolutions on
// maps stored height x width x channels (channels fastest), each with a kernel for CPUs that
// have AVX2 and FMA (chosen at run time) beside the portable one.

namespace orthoface::vision {

// y (n x m) = x (n x k) w (k x m) + bias (m), all row-major and dense. `vector_units` lets the
// AVX2 + FMA kernel run when the CPU has them (m must then be a multiple of 16, else the
// portable product runs). A large product shares its rows among OpenCV's threads
// (cv::parallel_for_), with the same result as on one. Throws std::invalid_argument on a null
// pointer or a size below 1.
void pointwise_product(const float* x, const float* w, const float* bias, float* y, int n, int k,
                       int m, bool vector_units = true);

// Depthwise 3x3 convolution without bias: y (oh x ow x c) from x (h x w x c), filters w[3][3][c],
// output pixel (r, q) centred on input (r * stride - pad_y + 1, q * stride - pad_x + 1), zero
// outside x. `vector_units` as above (c must be a multiple of 8). Throws std::invalid_argument on
// a null pointer, a size below 1 or a stride outside 1..2.
void depthwise3x3(const float* x, int h, int w, int c, const float* filters, int stride, int pad_y,
                  int pad_x, float* y, int oh, int ow, bool vector_units = true);

// Whether this CPU runs the AVX2 + FMA kernels.
bool has_vector_units();

}  // namespace orthoface::vision
