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

}  // namespace sanguis
