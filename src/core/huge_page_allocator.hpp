#pragma once
// An allocator for large arrays that asks Linux for transparent huge pages (2 MiB) where
// the system leaves them to the program (`/sys/kernel/mm/transparent_hugepage/enabled`
// set to `madvise`, Debian's default). What it buys, measured: memory the process gets
// fresh from the system is faulted in 2 MiB at a time instead of 4 KiB, so a regrid of
// the adaptive flow, which grows fields and builds multigrid levels, spends about a
// quarter less time (docs/performance.md, "Huge pages for the flow fields"); the
// kernels themselves ran no faster (the address translations were not what held them).
// Arrays from kThreshold on are aligned to 2 MiB and advised before the container
// touches them. Limits: memory glibc hands back from its own heap (after a large block
// is freed it raises its mmap threshold, up to 32 MiB) may have been touched already
// and stays on small pages; with `defrag = madvise` a fault in advised memory may wait
// for the kernel to compact memory; where the advice is refused or unknown (another
// kernel, another system) the memory is the same as without it. SANGUIS_HUGE_PAGES=0 in
// the environment withholds the advice (same alignment), for comparisons.
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <string_view>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace sanguis {

/// Whether large arrays get the huge-page advice (SANGUIS_HUGE_PAGES=0: not), read once.
inline bool huge_pages_advised() {
  static const bool advised = [] {
    const char* setting = std::getenv("SANGUIS_HUGE_PAGES");
    return setting == nullptr || std::string_view(setting) != "0";
  }();
  return advised;
}

template <typename T>
struct HugePageAllocator {
  using value_type = T;
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;
  /// Arrays from this size on are aligned to huge pages and advised (smaller ones would
  /// waste most of a 2 MiB page).
  static constexpr std::size_t kThreshold = 2 * kHugePage;

  HugePageAllocator() = default;
  template <typename U>
  constexpr HugePageAllocator(const HugePageAllocator<U>& /*unused*/) noexcept {}

  [[nodiscard]] T* allocate(std::size_t n) {
    // Room for the rounding up to whole huge pages below.
    if (n > (std::numeric_limits<std::size_t>::max() - kHugePage) / sizeof(T)) {
      throw std::bad_array_new_length();
    }
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kThreshold) return std::allocator<T>{}.allocate(n);
    const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Advice only: a refusal (no THP in this kernel) leaves ordinary pages.
    if (huge_pages_advised()) (void)madvise(p, rounded, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kThreshold) {
      std::allocator<T>{}.deallocate(p, n);
    } else {
      std::free(p);
    }
  }

  template <typename U>
  bool operator==(const HugePageAllocator<U>& /*unused*/) const noexcept {
    return true;
  }
};

}  // namespace sanguis
