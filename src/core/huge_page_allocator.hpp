#pragma once
// An allocator for large arrays that asks Linux for transparent huge pages (2 MiB) where
// the system leaves them to the program (`/sys/kernel/mm/transparent_hugepage/enabled`
// set to `madvise`, Debian's default). A sweep over fields of tens of megabytes touches
// a new 4 KiB page every 512 doubles, and a kernel that reads the neighbours of a block
// in place touches several pages at once; with 4 KiB pages their translations do not
// fit the TLB (2048 entries cover 8 MiB), with 2 MiB pages they do. The advice is given
// before the first touch (the container zero-fills after allocate), so the pages are
// faulted in as huge pages. Small arrays (below kThreshold) come from the usual
// allocator; where the advice is refused or unknown, the memory is the same as without
// it. SANGUIS_HUGE_PAGES=0 in the environment withholds the advice (same alignment), for
// comparisons. docs/performance.md, "Huge pages for the flow fields".
#include <cstddef>
#include <cstdlib>
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
