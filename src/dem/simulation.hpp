#pragma once
// One DEM system and its time loop (thesis Fig. 2.1): broad phase (when the
// Verlet lists are stale), contact forces with memory, integration.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dem/contact_list.hpp"
#include "dem/contact_parameters.hpp"
#include "dem/domain.hpp"
#include "dem/neighbor_search.hpp"
#include "dem/obstacles.hpp"
#include "dem/particle_exchange.hpp"
#include "dem/particle_shape.hpp"
#include "dem/particle_store.hpp"
#include "dem/time_integrator.hpp"

namespace sanguis::dem {

// Contact parameters for every ordered pair of materials (symmetric).
class ContactTable {
 public:
  ContactTable() = default;
  explicit ContactTable(std::size_t materials)
      : n_(materials), table_(materials * materials), defined_(materials * materials, false) {}
  void set(std::size_t a, std::size_t b, const ContactParameters& p) {
    table_[a * n_ + b] = p;
    table_[b * n_ + a] = p;
    defined_[a * n_ + b] = defined_[b * n_ + a] = true;
  }
  const ContactParameters& get(std::size_t a, std::size_t b) const { return table_[a * n_ + b]; }
  bool defined(std::size_t a, std::size_t b) const { return defined_[a * n_ + b]; }
  std::size_t materials() const { return n_; }
  // Row-major materials x materials array (get(a, b) is data()[a * materials() + b]).
  const ContactParameters* data() const { return table_.data(); }

 private:
  std::size_t n_ = 0;
  std::vector<ContactParameters> table_;
  std::vector<bool> defined_;
};

// Particles poured into a box-shaped region at a given rate during the run: each is
// placed at a random position (seeded) where its bounding sphere overlaps nothing; when
// the region is full the insertion waits for room.
struct PourSource {
  std::int32_t material = 0;
  std::int32_t species = -1;  // shape index, or -1 for spheres
  double radius = 0.0;        // sphere radius, or the body's bounding radius [m]
  double density = 0.0;       // [kg/m^3]
  bool random_orientation = true;
  Quaternion orientation;       // when not random
  Vec3 region_min, region_max;  // [m]
  Vec3 velocity;                // initial velocity [m/s]
  double rate = 0.0;            // particles per second
  double start = 0.0;           // [s]
  std::int64_t count = 0;       // how many in all
  std::int64_t inserted = 0;    // how many so far (state)
};

struct DemSetup {
  Domain domain;
  Vec3 gravity;            // [m/s^2]
  double time_step = 0.0;  // [s]
  IntegratorKind integrator = IntegratorKind::kLeapfrog;
  double skin = 0.0;               // Verlet skin [m]; 0 -> 0.1 x smallest diameter
  double max_overlap_ratio = 0.5;  // overlap / R beyond which the run stops as unstable
  int threads = 1;                 // OpenMP threads; results are bitwise the same for any count
  // The particles are re-sorted in memory along a space-filling curve (Z-order of the
  // linked cells, NeighborSearch::space_keys) when the simulation is built and every
  // this many steps (with a list rebuild); 0: never. Contacts are listed and
  // summed in storage order, so neighbours share cache lines and each thread's slab
  // its own stretch of memory. Results are the same bits for any thread count and
  // process count (a decomposed run sorts at the same steps); a different interval gives
  // a different, equally valid summation order. Outputs list particles by id.
  std::int64_t storage_sort_interval = 2000;
  std::size_t particles_per_thread =
      0;  // fewer per thread: fewer threads (0: 500 with bodies, 4000 spheres)
  // With bodies each thread takes up to 4 slabs, as many as leave at most this share
  // of the particles with a contact across slabs (simulation.cpp, kBodySlabsPerThread).
  double most_shared_fraction = 0.15;
  // Flat faces (boxes, polyhedra, obstacle facets) touch through contact patches
  // (body_contacts.hpp); false: at one point per element pair as in thesis §2.3 and
  // Grains3D (GJK's closest points; the overlap-weighted face centre against planes).
  bool contact_patches = true;
  // Two bodies that touch through several pairs of elements (two crosses: up to four
  // element contacts, each with its own memory) get the sum of those contacts' forces and
  // torques (false), or their mean (true): Grains3D, which ran the thesis' crosses (ch. 3),
  // divides each element contact's force and torque by the number of element contacts
  // between the two (Rakotonirina et al. 2019, composite particles). The same between a
  // body and an obstacle. The memories are the contacts' own either way.
  bool mean_element_contacts = false;
  // At the start of the step from this time every contact forgets its memory (the
  // tangential and rolling springs, a patch's twist): the contacts go on, their springs
  // start again from zero, as in a run reloaded from positions and velocities alone (a
  // pour saved without its contact history). Infinity: never.
  double forget_contact_memory_at = std::numeric_limits<double>::infinity();
  std::vector<std::string> material_names;
  ContactTable contacts;
  std::vector<Obstacle> obstacles;
  std::vector<ParticleShape> shapes;
  std::vector<PourSource> pour;
  std::uint64_t pour_seed = 0;  // species table (ParticleStore::species); spheres may omit it
  // Largest bounding radius the linked cells must serve beyond the particles present (a
  // process of a decomposed run receives ghosts later) [m]; 0: the particles' own.
  double largest_radius = 0.0;
  // The step the particles' state is at (time = start_step x time_step): a process of a
  // decomposed restart starts from a checkpoint's state, obstacles at their pose then.
  std::int64_t start_step = 0;
  ParticleStore particles;
};

struct DemDiagnostics {
  double time = 0.0;
  double kinetic_energy_translational = 0.0;  // [J]
  double kinetic_energy_rotational = 0.0;     // [J]
  double mean_velocity = 0.0;                 // mean |v| over the mobile particles [m/s]
  double max_velocity = 0.0;                  // [m/s]
  double mean_angular_velocity = 0.0;         // mean |omega| [rad/s]
  std::int64_t particle_contacts = 0;         // touching particle pairs
  std::int64_t wall_contacts = 0;             // touching particle-obstacle pairs
  double max_overlap_ratio = 0.0;             // max overlap / smaller radius
  std::int64_t deep_contacts = 0;             // body contacts deeper than the crusts
  std::int64_t mobile_particles = 0;          // the means' population (fixed ones excluded)
};

// A stretch of one block's sphere-pair group (positions [begin, end) in
// BlockContacts::of(b)). `direct`: the contacts are consecutive in the pair list and
// touch no shared particle, so the block sums them as the serial loop does, without the
// per-contact shared-particle tests and index lookups (compute_forces).
struct PairRun {
  std::uint32_t begin = 0, end = 0;
  bool direct = false;
};

// The contacts of one list grouped by thread block, each group in increasing contact
// index (CSR layout).
struct BlockContacts {
  std::vector<std::uint32_t> offset, index, fill;
  void build(const std::vector<std::uint32_t>& first, const std::vector<std::uint32_t>& block,
             std::size_t blocks);
  std::span<const std::uint32_t> of(std::size_t b) const {
    return {index.data() + offset[b], index.data() + offset[b + 1]};
  }
};

// The threads' slabs when there are more slabs than threads: thread t owns the run
// [next[t], end[t]) of neighbouring slabs and takes them from the front; a thread with
// none left takes the last slab of the thread with the most left (compute_forces).
// Called by one thread at a time.
struct SlabQueue {
  std::vector<std::ptrdiff_t> next, end;
  void start(std::ptrdiff_t slabs, int threads);
  std::ptrdiff_t take(int thread);  // a slab, or -1 when none is left
};

class DemSimulation {
 public:
  explicit DemSimulation(DemSetup setup);

  // Advances one time step.
  void step();
  // Advances until time() >= t (within half a step).
  void run_until(double t);

  double time() const { return static_cast<double>(step_) * setup_.time_step; }
  std::int64_t step_index() const { return step_; }
  double time_step() const { return setup_.time_step; }
  const DemSetup& setup() const { return setup_; }
  const ParticleStore& particles() const { return setup_.particles; }
  ParticleStore& particles() { return setup_.particles; }
  const ContactList& particle_contacts() const { return pairs_; }
  const ContactList& wall_contacts() const { return walls_; }
  const BodyContactList& body_contacts() const { return body_pairs_; }
  const BodyContactList& body_wall_contacts() const { return body_walls_; }
  TimeIntegrator& integrator() { return integrator_; }
  const NeighborSearch& neighbor_search() const { return search_; }
  // How the thread blocks walk their sphere pairs (empty on one thread), for tests.
  const std::vector<PairRun>& pair_runs() const { return pair_runs_; }
  int threads() const { return threads_; }  // threads in use (small systems run serially)
  // The threads' slabs (build_blocks): slab b's sphere pairs, for tests.
  const BlockContacts& slab_pairs() const { return block_pairs_; }

  DemDiagnostics diagnostics() const;

  // Bit-for-bit restart: everything that influences later steps is saved.
  void save_checkpoint(const std::filesystem::path& file) const;
  // Loads a checkpoint written by a simulation built from the same setup.
  void load_checkpoint(const std::filesystem::path& file);

  // Sorts the particles along space now (what the run does every storage_sort_interval
  // steps): new keys, storage in (key, id) order, lists
  // rebuilt, every memory carried over. One process only (a decomposed run sorts as it
  // exchanges particles). Local indices change: find particles by id.
  void sort_storage();
  // New sort keys (NeighborSearch::space_keys) for the particles, layered along the
  // longest axis of all the particles' extent (collective in a decomposed run, where the
  // processes then exchange particles in key order); a no-op when the sort is off.
  void assign_sort_keys();

  // Recomputes forces at the current state (after the state was edited by hand).
  void refresh_forces();
  // Sets every contact's memory to zero (DemSetup::forget_contact_memory_at does it
  // during a run): tangential springs, rolling springs and the patches' twist moments.
  void forget_contact_memory();

  // Domain decomposition (particle_exchange.hpp). The exchange is not owned; nullptr: alone.
  void set_exchange(ParticleExchange* exchange) { exchange_ = exchange; }
  // Per particle, 1 for a ghost (a copy of a particle another process owns); empty when
  // every particle is owned. Ghosts take part in contacts with owned particles only, and
  // count in no diagnostic.
  const std::vector<std::uint8_t>& ghost_flags() const { return ghost_; }
  bool is_ghost(std::size_t i) const { return !ghost_.empty() && ghost_[i] != 0; }
  std::size_t owned_count() const;
  // {smallest volume-equivalent radius, largest bounding radius} of a setup, particles
  // to be poured included: the default skin and the linked-cell size follow from them.
  static std::pair<double, double> radius_bounds(const DemSetup& setup);
  // Sets the step counter (a decomposed restart continues the checkpoint's count).
  void set_step_index(std::int64_t step) { step_ = step; }
  // Every contact with its memory, keyed by particle ids.
  std::vector<ContactMemory> export_contacts() const;
  // Replaces the particles mid-step (between the drift and the forces): the new set must
  // be in increasing (sort key, id) order, `half_velocity` / `half_angular` are leapfrog's mid-step
  // values per particle; the lists are rebuilt and each contact takes its memory from
  // `contacts` (sorted by ContactMemory::key) when found there.
  void replace_particles(ParticleStore particles, std::vector<std::uint8_t> ghost,
                         std::vector<Vec3> half_velocity, std::vector<Vec3> half_angular,
                         std::span<const ContactMemory> contacts);

 private:
  void compute_forces();
  void choose_threads();
  void rebuild_lists();
  void build_incidence();
  void build_blocks();
  void build_pair_runs();
  void split_body_contacts();
  void pour_particles();
  void check_state() const;
  void import_contacts(std::span<const ContactMemory> contacts);
  bool sort_due() const;
  void compute_sort_keys();
  void rebuild_sorted();

  DemSetup setup_;
  ParticleExchange* exchange_ = nullptr;
  std::vector<std::uint8_t> ghost_;
  TimeIntegrator integrator_;
  NeighborSearch search_;
  ContactList pairs_, walls_;
  std::int64_t step_ = 0;
  double max_overlap_ratio_ = 0.0;
  std::int64_t touching_pairs_ = 0, touching_walls_ = 0;
  int threads_ = 1;
  // Threaded force gather (see compute_forces): per-contact outcomes and, per particle,
  // its contacts in increasing index. Rebuilt with the lists, not part of the state.
  std::vector<ContactOutcome> pair_buffer_, wall_buffer_;
  std::vector<std::uint32_t> incident_offset_, incident_, incident_fill_, wall_offset_;
  // Contacts involving non-spherical bodies, element by element (body_contacts.hpp).
  bool has_bodies_ = false;
  // The step DemSetup::forget_contact_memory_at falls on; -1: never.
  std::int64_t forget_memory_step_ = -1;
  BodyContactList body_pairs_, body_walls_;
  std::vector<ContactOutcome> body_pair_buffer_, body_wall_buffer_;
  // With mean_element_contacts: the outcomes of one pair of bodies' element contacts, one
  // buffer per thread, kept between steps so that the time loop allocates nothing.
  std::vector<std::vector<ContactOutcome>> element_groups_;
  // Per slot: whether the contact touched this step (written for the contacts of shared
  // particles, the only ones the gather reads; the outcome only when it touched).
  std::vector<std::uint8_t> pair_touching_, wall_touching_, body_pair_touching_,
      body_wall_touching_;
  std::vector<std::uint32_t> body_incident_offset_, body_incident_, body_wall_offset_;
  // Threads (see compute_forces): space cut into one slab per thread, each with its
  // contacts of every list; `shared_` marks the particles with a contact in another
  // slab, summed by the gather, while every other particle accumulates directly in its
  // slab's loop.
  BlockContacts block_pairs_, block_walls_, block_body_pairs_, block_body_walls_;
  std::vector<std::uint32_t> shared_list_;
  std::vector<std::uint8_t> shared_;
  // The sphere-pair group of block b as runs pair_runs_[pair_run_offset_[b] ..
  // pair_run_offset_[b + 1]), in order (build_pair_runs).
  std::vector<PairRun> pair_runs_;
  std::vector<std::uint32_t> pair_run_offset_;
  SlabQueue slab_queue_;
  std::int64_t deep_contacts_ = 0;
  std::mt19937_64 pour_rng_;  // element contacts whose overlap exceeded the crusts
};

}  // namespace sanguis::dem
