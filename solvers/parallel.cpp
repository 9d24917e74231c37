// Fork-join parallel loop (see parallel.h).
#include "solvers/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace bf {

int hardware_threads(int requested) {
  return requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void parallel_for(int64_t n, const std::function<void(int64_t, int64_t)>& body, int threads) {
  if (n <= 0) return;
  // One contiguous chunk per thread, run by the index loop below.
  const int64_t t = std::min<int64_t>(hardware_threads(threads), n);
  parallel_for_each(t, [&](int64_t k) { body(n * k / t, n * (k + 1) / t); }, static_cast<int>(t));
}

void parallel_for_each(int64_t n, const std::function<void(int64_t)>& body, int threads) {
  if (n <= 0) return;
  const int64_t t = std::min<int64_t>(hardware_threads(threads), n);
  std::atomic<int64_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto run = [&] {
    for (int64_t i = next++; i < n; i = next++) {
      try {
        body(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = n;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(size_t(t - 1));
  for (int64_t k = 1; k < t; ++k) pool.emplace_back(run);
  run();
  for (std::thread& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace bf
