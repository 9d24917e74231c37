// A minimal fork-join loop over an index range on all cores (docs/design.md §6:
// "inside one process, use all cores"), for embarrassingly parallel loops such
// as tabulating a BRDF. No pool is kept between calls.
#pragma once

#include <cstdint>
#include <functional>

namespace bf {

// The thread count a `threads` option asks for: `requested` when > 0, else
// the hardware threads (at least 1). The one definition of "0 = all cores".
int hardware_threads(int requested = 0);

// Calls body(begin, end) on disjoint chunks covering [0, n), from up to
// `threads` threads (0 = std::thread::hardware_concurrency()); the calling
// thread takes part. Chunks are contiguous and in order per thread, so a body
// writing only its own indices needs no locking. The first exception thrown
// by any chunk is rethrown after all threads joined. n <= 0 does nothing.
void parallel_for(int64_t n, const std::function<void(int64_t begin, int64_t end)>& body,
                  int threads = 0);

// Calls body(i) for every i in [0, n), from up to `threads` threads (0 = all
// cores), each thread taking the next index as it finishes one (for items of
// unequal cost: order them costliest first). The calling thread takes part.
// A body writing only its own index needs no locking, and results by index do
// not depend on the scheduling. After the first exception no further index is
// started; it is rethrown after all threads joined. n <= 0 does nothing.
void parallel_for_each(int64_t n, const std::function<void(int64_t i)>& body, int threads = 0);

}  // namespace bf
