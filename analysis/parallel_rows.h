#pragma once
// Work split over the hardware threads for model/ (not public API).

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace orthoface::analysis::detail {

// Threads parallel_rows uses for n rows: the hardware threads, but at least `min_rows` rows
// each.
inline int row_threads(int n, int min_rows = 64) {
  return std::clamp(int(std::thread::hardware_concurrency()), 1, std::max(1, n / min_rows));
}

struct NoFinish {
  template <class Worker>
  void operator()(Worker&, int) const {}
};

// Rows [0, n) filled by `fill_row(worker, row)` on row_threads(n) threads, each worker with its
// own scratch state made by `make_worker(thread_index)` and handed to `finish(worker,
// thread_index)` when the rows run out (e.g. to collect per-thread results). Rows that are
// large pieces of work (blocks) can lower `min_rows`, the fewest rows worth a thread.
template <class MakeWorker, class FillRow, class Finish = NoFinish>
void parallel_rows(int n, MakeWorker make_worker, FillRow fill_row, Finish finish = {},
                   int min_rows = 64) {
  const int threads = row_threads(n, min_rows);
  std::atomic<int> next{0};
  auto run = [&](int index) {
    auto worker = make_worker(index);
    for (int row = next++; row < n; row = next++) fill_row(worker, row);
    finish(worker, index);
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(run, k);
  run(0);
  for (auto& t : pool) t.join();
}

}  // namespace orthoface::analysis::detail
