#pragma once
// Spatial domain decomposition of a DEM system over MPI processes (issue #5).
//
// The domain is cut into slabs along one axis; each process owns the particles
// whose centres lie in its slab and holds ghost copies of the particles of other
// slabs within a band of width 2 R_max + skin (every pair that can be a Verlet
// candidate of an owned particle). Each process evaluates the contacts that
// involve at least one owned particle, so an owned particle sees all its
// contacts and no force is sent back. Between two list rebuilds the ghost set is
// fixed and only the ghosts' state travels (after each drift); at a rebuild,
// which all processes do at the same step, the slab bounds are moved to
// balance the particle counts, particles move to their new owners with their
// leapfrog mid-step velocities and the memories of their contacts (keyed by
// particle ids), and the ghosts are rebuilt.
//
// Particles are kept in increasing (sort key, id) order on every process, as one
// process stores them (ParticleStore::sort_key), so each contact is oriented and
// each particle's contacts are summed in the same order as in a single-process run
// from the same state: the particle
// states are bitwise those of one process (checked by tests/dem/dem_mpi_check).
// Only the reductions of the diagnostics change with the process count.
//
// Checkpoints are gathered into the one-process format, so a run may continue on
// another number of processes (e.g. pour on one, collapse on several).
//
// Limits: leapfrog only, no pouring during the run (the insertion test needs
// all particles; a run may be restarted on several processes once its pouring is
// over), periodic axes other than the slab axis are handled locally (they never
// cross processes).
#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <mpi.h>

#include "dem/particle_exchange.hpp"
#include "dem/simulation.hpp"

namespace sanguis::dem {

class SlabDecomposition final : public ParticleExchange {
 public:
  // `axis`: 0, 1, 2, or -1 for the longest axis of the domain.
  explicit SlabDecomposition(MPI_Comm comm, int axis = -1);

  // The share of `full` (the whole system, the same on every process) this process
  // starts with: the particles of its slab, slabs cut at equal particle counts.
  DemSetup local_setup(const DemSetup& full);
  // Attaches to a simulation built from local_setup(): adds the ghosts and recomputes
  // the forces of the initial state (contacts start without memory, as in one process).
  void attach(DemSimulation& simulation);
  // Restart: attaches to a simulation built from local_setup(whole.setup()), where `whole`
  // holds a checkpoint of the whole system (written by any number of processes); the
  // state, forces and contact memories continue from it.
  void attach_restart(DemSimulation& simulation, const DemSimulation& whole);
  // Writes the checkpoint of the whole system in the one-process format (a run may
  // restart from it on any number of processes): the state is gathered on process 0 into
  // `whole`, a simulation of the same case there (unused elsewhere). Collective.
  void save_checkpoint(const DemSimulation& simulation, DemSimulation* whole,
                       const std::filesystem::path& file) const;

  bool any(bool local) override;
  void bounds(Vec3& low, Vec3& high) override;
  void refresh_ghosts(DemSimulation& simulation) override;
  void redistribute(DemSimulation& simulation) override;

  // Diagnostics of the whole system (sums, means and maxima over the processes).
  DemDiagnostics diagnostics(const DemSimulation& simulation) const;

  int rank() const { return rank_; }
  int ranks() const { return ranks_; }
  int axis() const { return axis_; }
  // Slab bounds along the axis: process r owns [bounds[r], bounds[r + 1]).
  const std::vector<double>& bounds() const { return bounds_; }
  std::int64_t ghosts() const { return ghost_count_; }
  // Bytes sent by this process since construction (particles, contacts and ghost
  // updates), for the communication model of docs/performance.md.
  std::int64_t bytes_sent() const { return bytes_sent_; }
  // Wall time spent in the exchanges (ghost refreshes, agreements, redistributions,
  // waits for slower processes included) [s].
  double exchange_seconds() const { return exchange_seconds_; }

  // Mid-step state of one particle in transit (trivially copyable).
  struct ParticleRecord;
  // What a ghost refresh sends per ghost (104 B).
  struct GhostState {
    Quaternion orientation;
    Vec3 position, velocity, angular_velocity;
  };

 private:
  void balance(const ParticleStore& p, const std::vector<std::uint8_t>& ghost);
  int owner_of(double coordinate) const;
  bool near_slab(double coordinate, int slab) const;
  std::vector<ParticleRecord> gather_records(const DemSimulation& simulation, int root) const;
  void exchange_ghosts(DemSimulation& simulation, std::vector<ParticleRecord> owned,
                       std::vector<ContactMemory> contacts);

  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  int requested_axis_ = -1;
  int axis_ = 0;
  bool periodic_axis_ = false;
  double axis_min_ = 0.0, axis_max_ = 1.0;
  double band_ = 0.0;  // ghost band width 2 R_max + skin [m]
  std::vector<double> bounds_;
  // Ghost bookkeeping between rebuilds: local indices sent to each process, and local
  // indices of the ghosts received from each process, in transfer order.
  std::vector<std::vector<std::uint32_t>> send_lists_, receive_lists_;
  std::vector<std::vector<GhostState>> send_states_, receive_states_;  // message buffers
  static constexpr int kGhostTag = 7301;
  std::int64_t ghost_count_ = 0;
  std::int64_t bytes_sent_ = 0;
  double exchange_seconds_ = 0.0;
};

}  // namespace sanguis::dem
