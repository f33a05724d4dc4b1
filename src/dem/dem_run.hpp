#pragma once
// Runs a DEM case to its end with outputs: ParaView files (particles, obstacles at
// their pose at each output time, the true surfaces of non-spherical bodies, the
// contact points and the branch network, each with a .pvd time index),
// diagnostics.csv, run.log, checkpoints and a progress line with ETA. Restart
// continues bit for bit from checkpoint.bin.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <vector>

#include <mpi.h>

#include "core/io/vtk.hpp"
#include "dem/dem_case.hpp"

namespace sanguis::dem {

struct RunOptions {
  std::filesystem::path output_dir;
  bool restart = false;   // continue from output_dir/checkpoint.bin
  bool quiet = false;     // no progress line
  double stop_at = -1.0;  // stop (with a checkpoint) at this time instead of end_time; < 0: off
  // Processes sharing the run (domain_decomposition.hpp); null or one process: alone. Each
  // process writes its piece of every frame (a block per process in the .pvd: one dataset
  // in ParaView); the first process writes the indexes, diagnostics.csv and run.log.
  MPI_Comm comm = MPI_COMM_NULL;
};

struct RunSummary {
  std::int64_t steps = 0;
  double simulated_time = 0.0;
  double wall_seconds = 0.0;
  bool settled = false;
  DemDiagnostics last;
};

// Throws InputError (bad restart files) or SimulationError (blow-up, after writing a
// final snapshot and checkpoint-free log entry).
RunSummary run_dem_case(const DemCase& c, const RunOptions& options, std::ostream& console);

// ------------------------------------------------------------------ output frames
// What one snapshot writes, as data (the run driver writes them; tests inspect them).

// Particle centres with point data radius (bounding radius for bodies), velocity,
// angular_velocity, force (contact force), orientation (4 components w, x, y, z: body ->
// space), id, coordination, material, species and spherical (1 for spheres: threshold on
// it before the Glyph filter, bodies are drawn by body_mesh).
io::PointCloud particle_cloud(const ParticleStore& p);

// Obstacles active at `time` as quads, at their pose at that time (translated and rotated
// by their motion): boxes by their 6 faces, planes by a square patch as wide as the
// domain's diagonal centred on the domain centre's projection. Cell data `obstacle`.
io::PolyMesh obstacle_mesh(const DemSetup& s, double time);

// The particles the simulation owns (all of them when it runs alone).
ParticleStore owned_particles(const DemSimulation& sim);

// The surface mesh of every non-spherical particle (ParticleShape::mesh) at its pose, as
// triangles, with cell data id, material, species and velocity (the particle's, per
// triangle). Spheres are left out (they are glyphs of the point cloud).
io::PolyMesh body_mesh(const std::vector<ParticleShape>& shapes, const ParticleStore& p);

enum class ContactKind : std::int32_t {
  kSpherePair = 0,  // two spheres
  kSphereWall = 1,  // a sphere and an obstacle
  kBodyPair = 2,    // two elements of two particles, at least one of them non-spherical
  kBodyWall = 3,    // an element of a non-spherical particle and an obstacle
};

// One touching contact at the current state of a simulation.
struct ContactRecord {
  ContactKind kind = ContactKind::kSpherePair;
  std::uint32_t first = 0;    // particle index (for pairs: the smaller id)
  std::uint32_t second = 0;   // particle index, or obstacle index for walls
  Vec3 point;                 // contact point (space frame; periodic: near the first particle)
  Vec3 normal;                // unit, from the first body towards the second
  double overlap = 0.0;       // [m]
  Vec3 force;                 // on the first body [N] (normal + tangential)
  double normal_force = 0.0;  // |Fn| of eq. 2.5 [N]
  Vec3 first_centre;          // centre of mass of the first particle
  Vec3 second_centre;         // of the second (its periodic image next to the first); walls: point
};

// The touching contacts of the simulation's current state, in list order: sphere pairs,
// sphere-walls, body (element) pairs, body-walls. The simulation keeps no per-contact
// forces, so they are re-evaluated here:
//  - geometry (overlap, normal, contact point) is recomputed from the positions and
//    orientations exactly as the force loop did: they do not change between the force
//    evaluation and the end of a step. Element contacts run GJK/EPA again from a copy of
//    the stored warm start (same poses: same simplex, same result);
//  - the force is evaluate_contact on a copy of the stored history with dt = 0: the
//    history already holds this step's tangential and rolling increments, so dt = 0
//    gives back the force the step applied (-kt delta - eta_t vt, saturated at mu |Fn|).
// Exact (to rounding) with Euler and Adams-Bashforth, whose forces see the velocities
// of the end of the step. Approximation with leapfrog: its forces saw the predicted
// velocity v_n + dt a_n, not the v_{n+1} available here, so the damping terms differ by
// eta dt (a_{n+1} - a_n) / 2: visible during impacts, nil at rest.
// Contacts of particles with non-finite positions (a blown-up state) are left out.
// In a decomposed run (domain_decomposition.hpp) a process returns its share: the
// contacts whose first particle it owns.
std::vector<ContactRecord> touching_contacts(const DemSimulation& sim);

// The contact frame, written as two files since a .vtp here carries only cell data:
// contacts/contacts_N.vtu (points) and contacts/branches_N.vtp (lines).
// `points` has one point per touching contact, at its contact point,
// with point data force (on the first body), normal_force, overlap, kind (ContactKind),
// first_id (particle id) and second_id (particle id, or obstacle index for walls).
// `branches` has one line per touching particle pair between the two centres (the branch
// vector; element contacts of one pair of particles are summed into one line), with cell
// data force_magnitude (|total force| between the two particles), normal_force (summed),
// kind, first_id and second_id: apply Tube scaled by force_magnitude for force chains.
struct ContactNetwork {
  io::PointCloud points;
  io::PolyMesh branches;
};
ContactNetwork contact_network(const DemSimulation& sim);

}  // namespace sanguis::dem
