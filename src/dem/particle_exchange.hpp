#pragma once
// How a DemSimulation shares its particles with other processes. Without one it
// runs alone; with one (domain_decomposition.hpp) it holds the particles its
// process owns plus ghost copies of other processes' particles near its region,
// and the time step calls the exchange at three fixed points (simulation.cpp):
// after the drift (ghost copies take their owners' new state), to agree on the
// list rebuild (every process rebuilds at the same step), and at a rebuild
// (particles change owner with their contact memories; new ghosts).
#include "core/vec3.hpp"

namespace sanguis::dem {

class DemSimulation;

class ParticleExchange {
 public:
  virtual ~ParticleExchange() = default;
  ParticleExchange() = default;
  ParticleExchange(const ParticleExchange&) = delete;
  ParticleExchange& operator=(const ParticleExchange&) = delete;

  // True on every process when `local` is true on any.
  virtual bool any(bool local) = 0;
  // The smallest and largest values over every process, component by component.
  virtual void bounds(Vec3& low, Vec3& high) = 0;
  // Ghost copies take the position, orientation and (predicted) velocities of their owners.
  virtual void refresh_ghosts(DemSimulation& simulation) = 0;
  // Moves particles to their new owners and rebuilds the ghosts and the contact lists.
  virtual void redistribute(DemSimulation& simulation) = 0;
};

}  // namespace sanguis::dem
