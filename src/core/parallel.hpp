#pragma once
// Loops over independent items on OpenMP threads. With one thread the loop runs
// plainly, without entering the OpenMP runtime (whose per-region cost dominates
// small systems stepped millions of times).
#include <cstddef>

namespace sanguis {

template <typename Body>
inline void parallel_for(std::size_t n, int threads, Body&& body) {
  if (threads > 1) {
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t i = 0; i < n; ++i) body(i);
  } else {
    for (std::size_t i = 0; i < n; ++i) body(i);
  }
}

// Whether pred(i) holds for some i in [0, n), all of them evaluated (no early exit, so
// the loop can vectorize); a boolean reduction, the same answer for any thread count.
template <typename Pred>
inline bool parallel_any(std::size_t n, int threads, Pred&& pred) {
  bool any = false;
  if (threads > 1) {
#pragma omp parallel for schedule(static) num_threads(threads) reduction(| : any)
    for (std::size_t i = 0; i < n; ++i) any |= pred(i);
  } else {
    for (std::size_t i = 0; i < n; ++i) any |= pred(i);
  }
  return any;
}

}  // namespace sanguis
