// Issue #5 asks for no allocation in the DEM time loop. This program counts every call of
// the global operator new (replaced below, which is why it is a program of its own and not
// part of sanguis_tests) while a sphere pile and a heap of crosses step on one and on two
// threads, and fails if a step that rebuilt no list allocated anything. A list rebuild
// (and the storage sort that comes with one) may allocate when the lists outgrow their
// capacity; between rebuilds the step works in the arrays it already has.
//
// Exit status 0 when every such step allocated nothing, 1 otherwise (ctest:
// DemSimulation.StepsBetweenRebuildsAllocateNothing).
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "core/config.hpp"
#include "dem/dem_case.hpp"
#include "falling_crosses.hpp"
#include "thrown_pile.hpp"

namespace {
std::atomic<long> g_allocations{0};

void* counted(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

void* counted_aligned(std::size_t size, std::align_val_t align) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  const auto a = static_cast<std::size_t>(align);
  const std::size_t rounded = (size + a - 1) / a * a;
  if (void* p = std::aligned_alloc(a, rounded == 0 ? a : rounded)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) {
  return counted(size);
}
void* operator new[](std::size_t size) {
  return counted(size);
}
void* operator new(std::size_t size, std::align_val_t align) {
  return counted_aligned(size, align);
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return counted_aligned(size, align);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

namespace {

using sanguis::dem::DemSimulation;

// Steps `sim` `steps` times; returns the number of steps that rebuilt no list yet
// allocated, and prints what it saw.
int allocating_steps(DemSimulation& sim, int steps, const std::string& name) {
  int bad = 0, quiet = 0;
  long worst = 0, at_rebuilds = 0;
  for (int n = 0; n < steps; ++n) {
    const std::int64_t rebuilds = sim.neighbor_search().rebuild_count();
    const long before = g_allocations.load();
    sim.step();
    const long allocated = g_allocations.load() - before;
    if (sim.neighbor_search().rebuild_count() != rebuilds) {
      at_rebuilds += allocated;
      continue;
    }
    ++quiet;
    if (allocated > 0) {
      ++bad;
      worst = std::max(worst, allocated);
    }
  }
  std::printf(
      "%s: %d steps, %d without a list rebuild, %d of them allocated (at most %ld); the "
      "rebuilds allocated %ld times\n",
      name.c_str(), steps, quiet, bad, worst, at_rebuilds);
  if (g_allocations.load() == 0) {  // the replacement above is not the one in use
    std::printf("%s: no allocation counted at all\n", name.c_str());
    return 1;
  }
  if (quiet < steps / 2) {
    std::printf("%s: too few steps without a rebuild to check anything\n", name.c_str());
    return 1;
  }
  return bad;
}

}  // namespace

int main() {
  int failures = 0;
  for (const int threads : {1, 2}) {
    {
      sanguis::dem::DemCase c = sanguis::dem::load_dem_case(
          sanguis::ConfigTable::parse_string(sanguis::dem::testing::kThrownPile, "pile.toml"),
          "pile.toml");
      c.setup.threads = threads;
      c.setup.particles_per_thread = 1;  // threads on this small system
      c.setup.storage_sort_interval = 500;
      DemSimulation sim(c.setup);
      for (int n = 0; n < 20; ++n) sim.step();  // first lists and buffers
      failures +=
          allocating_steps(sim, 2000, "sphere pile, " + std::to_string(threads) + " thread(s)") > 0;
    }
    {
      DemSimulation sim(sanguis::dem::testing::falling_crosses(
          threads, [](int n) { return static_cast<std::int64_t>(n); }));
      for (int n = 0; n < 20; ++n) sim.step();
      failures += allocating_steps(
                      sim, 2000, "falling crosses, " + std::to_string(threads) + " thread(s)") > 0;
    }
    {
      sanguis::dem::DemSetup s = sanguis::dem::testing::falling_crosses(
          threads, [](int n) { return static_cast<std::int64_t>(n); });
      s.mean_element_contacts = true;  // element_contacts = "mean": grouped outcomes
      DemSimulation sim(std::move(s));
      for (int n = 0; n < 20; ++n) sim.step();
      failures += allocating_steps(sim, 2000,
                                   "falling crosses, element contacts averaged, " +
                                       std::to_string(threads) + " thread(s)") > 0;
    }
  }
  std::printf(failures == 0 ? "no allocation between list rebuilds\n"
                            : "FAILED: steps without a list rebuild allocated\n");
  return failures == 0 ? 0 : 1;
}
