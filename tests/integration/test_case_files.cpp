// Every case file shipped in cases/ loads (keys valid, particles placed, parameters
// resolved) and takes a few steps without blowing up.
#include <gtest/gtest.h>

#include <filesystem>

#include "dem/dem_case.hpp"

namespace sanguis::dem {
namespace {

TEST(ShippedCases, EveryDemCaseLoadsAndSteps) {
  const std::filesystem::path dir = std::filesystem::path(SANGUIS_SOURCE_DIR) / "cases" / "dem";
  int cases = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    DemCase c = load_dem_case(entry.path());
    // Particles at t = 0, or poured during the run.
    EXPECT_GT(c.setup.particles.size() + c.setup.pour.size(), 0u);
    c.setup.threads = 1;
    DemSimulation sim(c.setup);
    for (int n = 0; n < 20; ++n) sim.step();
    EXPECT_LT(sim.diagnostics().max_overlap_ratio, c.setup.max_overlap_ratio);
    ++cases;
  }
  EXPECT_GE(cases, 4);
}

}  // namespace
}  // namespace sanguis::dem
