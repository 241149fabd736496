#pragma once
// Rows of independent work split over OpenCV's thread pool for analysis/ (not public API).

#include <algorithm>
#include <cstdint>

#include <opencv2/core/utility.hpp>

namespace orthoface::analysis::detail {

// Chunks parallel_rows cuts n rows into: two per OpenCV thread (so uneven rows balance), but
// at least `min_rows` rows each.
inline int row_chunks(int n, int min_rows = 64) {
  return std::clamp(2 * cv::getNumThreads(), 1, std::max(1, n / std::max(1, min_rows)));
}

struct NoFinish {
  template <class Worker>
  void operator()(Worker&, int) const {}
};

// Rows [0, n) filled by `fill_row(worker, row)` in row_chunks(n) contiguous chunks run by
// cv::parallel_for_, each chunk with its own scratch state made by `make_worker(chunk)` and
// handed to `finish(worker, chunk)` when its rows are done (e.g. to collect per-chunk results
// into a vector of row_chunks(n) slots). Rows that are large pieces of work (blocks) can lower
// `min_rows`, the fewest rows worth a chunk.
template <class MakeWorker, class FillRow, class Finish = NoFinish>
void parallel_rows(int n, MakeWorker make_worker, FillRow fill_row, Finish finish = {},
                   int min_rows = 64) {
  const int chunks = row_chunks(n, min_rows);
  cv::parallel_for_(
      cv::Range(0, chunks),
      [&](const cv::Range& range) {
        for (int c = range.start; c < range.end; ++c) {
          auto worker = make_worker(c);
          const int lo = int(int64_t(n) * c / chunks), hi = int(int64_t(n) * (c + 1) / chunks);
          for (int row = lo; row < hi; ++row) fill_row(worker, row);
          finish(worker, c);
        }
      },
      chunks);
}

}  // namespace orthoface::analysis::detail
