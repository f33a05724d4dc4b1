#pragma once
// Broad phase (thesis app. A.1): a linked-cell grid whose cells are at least one
// cut-off (largest diameter + skin) wide, building Verlet lists of particle pairs
// and particle-obstacle pairs within cut-off + skin. Lists are rebuilt only when
// some particle has moved more than half the skin since the last build.
#include <array>
#include <cstdint>
#include <vector>

#include "dem/contact_list.hpp"
#include "dem/domain.hpp"
#include "dem/obstacles.hpp"
#include "dem/particle_store.hpp"

namespace sanguis::dem {

class NeighborSearch {
 public:
  NeighborSearch() = default;
  NeighborSearch(const Domain& domain, double skin, double max_radius);

  // True when the lists may miss a contact: a particle, or a point of a moving obstacle,
  // has moved more than skin / 2 since the last build. The particle pass runs on
  // `threads` OpenMP threads (a pass over every position at every step: serial, it was
  // a few per cent of a two-thread step).
  bool needs_rebuild(const ParticleStore& particles, int threads = 1) const;
  bool needs_rebuild(const ParticleStore& particles, const std::vector<Obstacle>& obstacles,
                     double time, int threads = 1) const;

  // Wraps periodic positions, bins particles and rebuilds both lists, carrying the
  // contact histories over. Obstacles inactive at `time` get no entries. With `ghost`
  // (one flag per particle), pairs of two ghosts and ghost-obstacle pairs are left out.
  // The search runs on `threads` OpenMP threads, each on ranges of particles with lists
  // of their own, joined in particle order: the lists are the same for any thread count.
  void rebuild(ParticleStore& particles, const std::vector<Obstacle>& obstacles, double time,
               ContactList& pairs, ContactList& walls, const std::uint8_t* ghost = nullptr,
               int threads = 1);

  // Each particle's place along a space-filling curve through the linked cells: the
  // layers of cells along `axis` one after the other, a Z-order (Morton) curve within
  // each layer; periodic positions wrapped. Sorting the storage by (key, id) puts
  // neighbours next to each other in memory, and the threads' slabs, cut along the same
  // axis, each in its own stretch of it (DemSimulation::sort_storage).
  std::vector<std::uint64_t> space_keys(const ParticleStore& particles, int axis) const;

  std::int64_t rebuild_count() const { return rebuilds_; }
  double skin() const { return skin_; }
  const std::vector<Vec3>& reference_positions() const { return reference_; }
  std::vector<Vec3>& reference_positions() { return reference_; }
  std::int64_t& rebuild_counter() { return rebuilds_; }
  double& reference_time() { return reference_time_; }
  double reference_time() const { return reference_time_; }  // of the last build [s]
  std::vector<Quaternion>& reference_orientations() { return reference_orientation_; }
  const Domain& domain() const { return domain_; }

 private:
  void bin(const ParticleStore& particles);
  std::int64_t cell_of(const Vec3& x) const;
  // The cell of x along each axis, clamped into the grid (a NaN coordinate gives 0).
  std::array<std::int64_t, 3> cell_coordinates(const Vec3& x) const;
  double obstacle_travel(const Obstacle& o, double t0, double t1) const;
  // Appends the particles j > i within cut-off + skin of particle i, in increasing order.
  void pairs_of(const ParticleStore& particles, std::size_t i, const std::uint8_t* ghost,
                std::vector<std::uint32_t>& out) const;
  // Fills `list` (fresh memories) with the entries find(i, out) appends for i = 0 .. n - 1,
  // in that order, the particles cut into ranges searched in parallel.
  template <typename Find>
  void collect(std::size_t n, int threads, ContactList& list, Find&& find);

  Domain domain_;
  double skin_ = 0.0;
  std::array<std::int64_t, 3> cells_{1, 1, 1};
  Vec3 cell_size_;
  std::vector<std::uint32_t> cell_start_;          // CSR offsets, size n_cells + 1
  std::vector<std::uint32_t> cell_members_;        // particle indices sorted by cell
  std::vector<Vec3> reference_;                    // positions at the last rebuild
  std::vector<Quaternion> reference_orientation_;  // orientations then (only with bodies)
  std::int64_t rebuilds_ = 0;
  double reference_time_ = 0.0;  // time of the last rebuild [s]
  ContactList scratch_;
  // One pair of buffers per range of particles (kept: no allocation once they have grown).
  std::vector<std::vector<std::uint32_t>> range_first_, range_second_;
  std::vector<std::size_t> range_offset_;
};

}  // namespace sanguis::dem
