// analysis/contact_statistics: force PDFs, fabric in the xz-plane, coordination
// numbers and wall loads on hand-made frames with known answers.
#include "dem/analysis/contact_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem/analysis/collapse.hpp"

namespace sanguis::dem::analysis {
namespace {

TEST(ContactHistogram, DensityIntegratesToTheFractionInside) {
  const Histogram h = histogram({0.1, 0.2, 0.6, 1.0, 5.0}, linear_edges(0.0, 1.0, 4));
  EXPECT_EQ(h.samples, 5u);
  EXPECT_EQ(h.counts, (std::vector<double>{2, 0, 1, 1}));
  double integral = 0.0;
  for (std::size_t b = 0; b < h.density.size(); ++b) integral += h.density[b] * 0.25;
  EXPECT_NEAR(integral, 0.8, 1e-12);  // 5.0 is outside
  const std::vector<double> e = log_edges(1e-3, 1e1, 4);
  EXPECT_NEAR(e[1], 1e-2, 1e-15);
  EXPECT_NEAR(e[4], 1e1, 1e-12);
}

TEST(ContactHistogram, AverageOfRunsIsBinwise) {
  const auto edges = linear_edges(0.0, 2.0, 2);
  const Histogram a = histogram({0.5}, edges), b = histogram({1.5}, edges);
  const Histogram m = average({a, b});
  EXPECT_DOUBLE_EQ(m.density[0], 0.5);
  EXPECT_DOUBLE_EQ(m.density[1], 0.5);
  EXPECT_THROW(average({a, histogram({1.0}, linear_edges(0.0, 3.0, 2))}), std::invalid_argument);
}

BranchFrame branches_of(const std::vector<std::pair<Vec3, Vec3>>& pairs,
                        const std::vector<double>& forces) {
  BranchFrame b;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    b.from.push_back(pairs[k].first);
    b.to.push_back(pairs[k].second);
    b.force_magnitude.push_back(forces[k]);
    b.first.push_back(static_cast<std::int64_t>(k));
    b.second.push_back(static_cast<std::int64_t>(k + 1));
  }
  return b;
}

TEST(ContactForces, ScaledByTheirMean) {
  const BranchFrame b = branches_of({{{}, {1, 0, 0}}, {{}, {1, 0, 0}}}, {1.0, 3.0});
  EXPECT_EQ(scaled_force_magnitudes(b), (std::vector<double>{0.5, 1.5}));
}

TEST(Fabric, VerticalChainsAreFullyAnisotropic) {
  // Branches along z (one pointing down): theta = 90 degrees, anisotropy 2.
  const BranchFrame b = branches_of({{{0, 0, 0}, {0, 0.3, 1}}, {{0, 0, 1}, {0, 0, 0}}}, {1, 1});
  const Fabric f = fabric_xz(b, 18);
  EXPECT_NEAR(f.anisotropy, 2.0, 1e-12);
  EXPECT_NEAR(f.principal_angle_deg, 90.0, 1e-9);
  EXPECT_EQ(f.angles.counts[9], 2.0);  // bin [90, 100)
}

TEST(Fabric, FourDirectionsAreIsotropic) {
  const double c = std::sqrt(0.5);
  const BranchFrame b = branches_of(
      {{{}, {1, 0, 0}}, {{}, {0, 0, 1}}, {{}, {c, 0, c}}, {{}, {-c, 0, c}}}, {1, 1, 1, 1});
  EXPECT_NEAR(fabric_xz(b, 4).anisotropy, 0.0, 1e-12);
}

// Three particles in a row (0-1-2), 1 and 2 touching the floor (obstacle 0), with
// particle 2 also a body touching 1 at two points.
TEST(Coordination, CountsPairsContactPointsAndWallContacts) {
  ParticleFrame p;
  p.id = {0, 1, 2};
  p.position = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}};
  p.mass = {1.0, 1.0, 2.0};
  BranchFrame b;
  b.from = {{0, 0, 1}, {1, 0, 1}};
  b.to = {{1, 0, 1}, {2, 0, 1}};
  b.force_magnitude = {1, 1};
  b.first = {0, 1};
  b.second = {1, 2};
  ContactPointFrame c;
  c.point = {{0.5, 0, 1}, {1.5, 0, 1}, {1.5, 0, 1.1}, {1, 0, 0}, {2, 0, 0}};
  c.force = {{}, {}, {}, {0, 0, 9.81}, {0.5, 0, 2 * 9.81}};
  c.kind = {0, 2, 2, 1, 3};
  c.first = {0, 1, 1, 1, 2};
  c.second = {1, 2, 2, 0, 0};

  const Coordination all = coordination(p, b, c, Region{});
  EXPECT_EQ(all.particles, 3u);
  EXPECT_DOUBLE_EQ(all.pair_coordination, 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(all.contact_point_coordination, 6.0 / 3.0);
  EXPECT_EQ(all.wall_contact_points.at(0), 2u);
  // 1 and 2 touch the floor; particle 0 alone touches none, with one neighbour.
  EXPECT_EQ(all.particles_touching_obstacles, 2u);
  EXPECT_DOUBLE_EQ(all.pair_coordination_away_from_obstacles, 1.0);

  Region right;
  right.min.x = 1.5;
  const Coordination r = coordination(p, b, c, right);
  EXPECT_EQ(r.particles, 1u);
  EXPECT_DOUBLE_EQ(r.pair_coordination, 1.0);
  EXPECT_DOUBLE_EQ(r.contact_point_coordination, 2.0);
  EXPECT_EQ(r.wall_contact_points.at(0), 1u);
  EXPECT_EQ(r.particles_touching_obstacles, 1u);
  EXPECT_DOUBLE_EQ(r.pair_coordination_away_from_obstacles, 0.0);  // none touches no obstacle

  const auto loads = wall_loads(p, c, 9.81);
  EXPECT_EQ(loads.at(0).contact_points, 2u);
  EXPECT_NEAR(loads.at(0).weight_fraction, 0.75, 1e-12);  // 3 m g of the 4 m g total
  EXPECT_NEAR(loads.at(0).force.x, 0.5, 1e-12);
}

TEST(Collapse, CentreOfMassIsMassWeighted) {
  ParticleFrame p;
  p.position = {{0, 0, 0}, {3, 0, 0}};
  p.velocity = {{1, 0, 0}, {0, 3, 4}};
  p.mass = {2.0, 1.0};
  EXPECT_DOUBLE_EQ(centre_of_mass(p).x, 1.0);
  EXPECT_DOUBLE_EQ(mean_speed(p), 3.0);
  p.mass.clear();  // older runs: equal weights
  EXPECT_DOUBLE_EQ(centre_of_mass(p).x, 1.5);
}

TEST(Collapse, RegimeFromHeightsAndLengths) {
  EXPECT_EQ(classify_regime(0.2, 0.1, 0.05, 0.2), FlowRegime::kCollapsed);
  EXPECT_EQ(classify_regime(0.2, 0.2, 0.05, 0.2), FlowRegime::kFractured);
  EXPECT_EQ(classify_regime(0.2, 0.199, 0.05, 0.052), FlowRegime::kStable);
  EXPECT_EQ(to_string(FlowRegime::kFractured), "fractured");
}

TEST(Collapse, AHaltIsALongStretchUnderTheLineBetweenTwoStretchesAboveIt) {
  // t / tau_c every 0.5; the speed starts the collapse, halts 0.02 for 2 tau_c, goes on.
  const std::vector<double> t = {0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0};
  const std::vector<double> v = {0.0, 0.1, 0.3, 0.04, 0.02, 0.02, 0.03, 0.2, 0.1, 0.01, 0.0};
  const Halts h = find_halts(t, v);
  EXPECT_EQ(h.count, 1);
  EXPECT_DOUBLE_EQ(h.longest, 2.0);  // from 1.5, the first sample under 0.05, to 3.5
  // The final stop (4.5 on) is no halt: nothing follows it. Before the start, no halt.
  const std::vector<double> quiet = {0.0, 0.01, 0.01, 0.01, 0.01, 0.2, 0.3, 0.1, 0.0, 0.0, 0.0};
  EXPECT_EQ(find_halts(t, quiet).count, 0);
  // Shorter than min_duration: a dip, not a halt; a lower line sees none either.
  EXPECT_EQ(find_halts(t, v, {0.05, 2.5}).count, 0);
  EXPECT_EQ(find_halts(t, v, {0.01, 1.0}).count, 0);
  // Two halts; the longest is reported.
  const std::vector<double> twice = {0.1, 0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.1, 0.0};
  const Halts h2 = find_halts(t, twice);
  EXPECT_EQ(h2.count, 2);
  EXPECT_DOUBLE_EQ(h2.longest, 2.0);
}

}  // namespace
}  // namespace sanguis::dem::analysis
