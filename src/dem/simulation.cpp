#include "dem/simulation.hpp"
#include "dem/slab_cuts.hpp"
#include "dem/sphere_pair_kernel.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "core/error.hpp"
#include "core/io/atomic_file.hpp"
#include "dem/body_contacts.hpp"
#include "geometry/separating_axes.hpp"

namespace sanguis::dem {

namespace {

// With bodies each thread owns a run of up to four neighbouring slabs and, when done,
// takes the last slab of the thread with the most left (SlabQueue): an element pair costs
// a GJK call or a bounding-ball test depending on how the bodies lie, which counting
// contacts cannot foresee. But every cut shares the particles on both sides, whose
// contacts go through the gather: as many slabs as leave at most
// DemSetup::most_shared_fraction of the particles shared. The 7000-cross benchmark
// column takes 4 per thread (8 % shared) and runs about 4 % faster in the median; the
// 1300 crosses of the experiments' box would share 35 % with 2 per thread and keep 1
// (docs/performance.md, "Where two threads lose their time, and slabs for bodies").
// Spheres keep one slab per thread, whose particles are that thread's in the
// integrator loop too (more were slower).
constexpr std::size_t kBodySlabsPerThread = 4;

}  // namespace

std::pair<double, double> DemSimulation::radius_bounds(const DemSetup& s) {
  // Smallest volume-equivalent radius (a cross's bounding sphere is 3x larger, and a skin
  // from it would swell the lists) and largest bounding radius, particles to come included.
  double r_max = s.largest_radius, r_min = std::numeric_limits<double>::infinity();
  for (const PourSource& src : s.pour) {
    r_max = std::max(r_max, src.radius);
    r_min = std::min(r_min, src.species >= 0
                                ? s.shapes[static_cast<std::size_t>(src.species)].equivalent_radius
                                : src.radius);
  }
  const ParticleStore& p = s.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    r_max = std::max(r_max, p.radius[i]);
    const bool body = !p.spherical[i] && static_cast<std::size_t>(p.species[i]) < s.shapes.size();
    r_min =
        std::min(r_min, body ? s.shapes[static_cast<std::size_t>(p.species[i])].equivalent_radius
                             : p.radius[i]);
  }
  if (r_max == 0.0) r_max = r_min = 1.0;
  if (!std::isfinite(r_min)) r_min = r_max;
  return {r_min, r_max};
}

DemSimulation::DemSimulation(DemSetup setup)
    : setup_(std::move(setup)), integrator_(setup_.integrator), step_(setup_.start_step) {
  ParticleStore& p = setup_.particles;
  if (!(setup_.time_step > 0.0)) throw std::invalid_argument("time step must be > 0");
  for (const PourSource& src : setup_.pour) has_bodies_ |= src.species >= 0;
  pour_rng_.seed(setup_.pour_seed);
  // On the step grid, so a restart from a checkpoint written at that step forgets too,
  // and one written later does not forget again.
  if (std::isfinite(setup_.forget_contact_memory_at)) {
    forget_memory_step_ = std::llround(setup_.forget_contact_memory_at / setup_.time_step);
  }
  // Default skin: 10% of the smallest diameter.
  const auto [r_min, r_max] = radius_bounds(setup_);
  if (setup_.skin <= 0.0) setup_.skin = 0.2 * r_min;
  const std::size_t n_materials = setup_.contacts.materials();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (static_cast<std::size_t>(p.material[i]) >= n_materials) {
      throw std::invalid_argument("particle material index out of range");
    }
  }
  search_ = NeighborSearch(setup_.domain, setup_.skin, r_max);
  for (const Obstacle& o : setup_.obstacles) {
    has_bodies_ |= std::holds_alternative<ShapeObstacle>(o.shape);  // element contacts
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.spherical[i]) continue;
    has_bodies_ = true;
    if (static_cast<std::size_t>(p.species[i]) >= setup_.shapes.size() ||
        setup_.shapes[static_cast<std::size_t>(p.species[i])].is_sphere()) {
      throw std::invalid_argument("a non-spherical particle has no shape in the species table");
    }
  }
  // Sorted at once: a random fill leaves ids, and so storage, scattered in space.
  if (sort_due()) {
    rebuild_sorted();
  } else {
    rebuild_lists();
  }
  compute_forces();
}

void DemSimulation::refresh_forces() {
  rebuild_lists();
  compute_forces();
}

void DemSimulation::forget_contact_memory() {
  // The stored normal stays: it only turns the (now zero) springs into the next plane.
  const auto unload = [](std::vector<ContactHistory>& histories) {
    for (ContactHistory& h : histories) {
      h.tangential_displacement = {};
      h.rolling_spring_torque = {};
    }
  };
  unload(pairs_.history);
  unload(walls_.history);
  for (BodyContactList* list : {&body_pairs_, &body_walls_}) {
    unload(list->history);
    std::fill(list->twist.begin(), list->twist.end(), 0.0);
  }
}

void DemSimulation::step() {
  const double dt = setup_.time_step;
  ParticleStore& p = setup_.particles;
  if (step_ == forget_memory_step_) forget_contact_memory();
  if (!setup_.pour.empty()) pour_particles();
  integrator_.advance(p, setup_.gravity, dt);
  ++step_;
  if (exchange_ == nullptr) {
    if (sort_due()) {
      rebuild_sorted();
    } else if (search_.needs_rebuild(p, setup_.obstacles, time(), threads_)) {
      rebuild_lists();
    }
    compute_forces();
    integrator_.finish(p, setup_.gravity, dt);
    if (step_ % 64 == 0) check_state();
    return;
  }
  // Ghosts first take their owners' drifted state, so every process sees the same
  // displacements and all rebuild at the step a single process would.
  exchange_->refresh_ghosts(*this);
  const bool sort = sort_due();  // the same on every process
  if (exchange_->any(sort || search_.needs_rebuild(p, setup_.obstacles, time(), threads_))) {
    // The processes sort their particles by the new keys as they exchange them.
    if (sort) assign_sort_keys();
    exchange_->redistribute(*this);
  }
  // A blow-up seen by one process stops them all (none may wait in a collective).
  std::string error;
  try {
    compute_forces();
    integrator_.finish(p, setup_.gravity, dt);
    if (step_ % 64 == 0) check_state();
  } catch (const SimulationError& e) {
    error = e.what();
  }
  if (exchange_->any(!error.empty())) {
    throw SimulationError(error.empty() ? "step " + std::to_string(step_) +
                                              ": another process stopped the run (see its message)"
                                        : error);
  }
}

void DemSimulation::pour_particles() {
  ParticleStore& p = setup_.particles;
  const std::size_t before = p.size();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double now = time();
  for (PourSource& src : setup_.pour) {
    if (now < src.start || src.inserted >= src.count) continue;
    const auto due = std::min<std::int64_t>(
        src.count, static_cast<std::int64_t>(std::floor((now - src.start) * src.rate)) + 1);
    while (src.inserted < due) {
      bool placed = false;
      for (int attempt = 0; attempt < 50 && !placed; ++attempt) {
        Vec3 x;
        for (int k = 0; k < 3; ++k) {
          const double lo = src.region_min[k] + src.radius, hi = src.region_max[k] - src.radius;
          x[k] = lo + (hi - lo) * unit(pour_rng_);
        }
        bool free = true;
        for (std::size_t i = 0; i < p.size() && free; ++i) {
          const double cut = p.radius[i] + src.radius;
          free = norm2(setup_.domain.minimum_image(p.position[i] - x)) >= cut * cut;
        }
        for (std::size_t o = 0; o < setup_.obstacles.size() && free; ++o) {
          const Obstacle& ob = setup_.obstacles[o];
          free = !ob.active(now) || sphere_gap(ob, now, x, src.radius).overlap <= 0.0;
        }
        if (!free) continue;
        const auto id = static_cast<std::int64_t>(p.size());
        if (src.species < 0) {
          p.add_sphere(id, src.material, src.radius, src.density, x, src.velocity, {});
        } else {
          const ParticleShape& sh = setup_.shapes[static_cast<std::size_t>(src.species)];
          Quaternion q = src.orientation;
          if (src.random_orientation) {
            q = normalized(
                {gauss(pour_rng_), gauss(pour_rng_), gauss(pour_rng_), gauss(pour_rng_)});
          }
          p.add_body(id, src.material, src.species, sh.bounding_radius, src.density * sh.volume,
                     src.density * sh.inertia_per_density, q, x, src.velocity, {});
        }
        // Stored last, so last in (sort key, id) order until the next sort.
        p.sort_key.back() = std::numeric_limits<std::uint64_t>::max();
        placed = true;
        ++src.inserted;
      }
      if (!placed) break;  // the region is full: try again next step
    }
  }
  // New particles have no contact yet; the lists are rebuilt before the next forces
  // (the particle count changed), and multistep histories start as free flight.
  if (p.size() != before) integrator_.extend_history(p, setup_.gravity);
}

void DemSimulation::run_until(double t) {
  while (time() < t - 0.5 * setup_.time_step) step();
}

namespace {

// The elements of particle i for the narrow phase: a sphere is one element, its centre
// point with a crust equal to its radius.
const geometry::ConvexShape kPointCore = geometry::Sphere{0.0};

struct ElementView {
  const geometry::ConvexShape* core;
  Vec3 position;           // space frame
  Quaternion orientation;  // element -> space
  double crust;
  double reach;
};

inline std::size_t element_count(const ParticleStore& p, const std::vector<ParticleShape>& shapes,
                                 std::size_t i) {
  return p.spherical[i] ? 1 : shapes[static_cast<std::size_t>(p.species[i])].elements.size();
}

inline ElementView element_view(const ParticleStore& p, const std::vector<ParticleShape>& shapes,
                                std::size_t i, std::size_t e, const Vec3& centre) {
  if (p.spherical[i]) return {&kPointCore, centre, Quaternion{}, p.radius[i], p.radius[i]};
  const ShapeElement& el = shapes[static_cast<std::size_t>(p.species[i])].elements[e];
  const Quaternion& q = p.orientation[i];
  return {&el.core, centre + rotate(q, el.position), q * el.orientation, el.crust, el.reach};
}

// Hands use(k, outcome) the outcome of the element contacts index(0), ..., index(count - 1)
// of `list`, in that order (indices in list order). With `mean`, the touching contacts of
// one pair of bodies, or of a body and an obstacle (consecutive entries with the same
// first and second: the list is sorted so), are divided by how many of them touch, as
// Grains3D does for composite particles (each contact force times 1/nbContact).
template <typename Index, typename Outcome, typename Use>
void element_contact_outcomes(const BodyContactList& list, Index index, std::size_t count,
                              bool mean, std::vector<ContactOutcome>& group, Outcome&& outcome,
                              Use&& use) {
  if (!mean) {
    for (std::size_t e = 0; e < count; ++e) use(index(e), outcome(index(e)));
    return;
  }
  for (std::size_t e = 0; e < count;) {
    const std::size_t k0 = index(e);
    std::size_t end = e + 1;
    while (end < count && list.first[index(end)] == list.first[k0] &&
           list.second[index(end)] == list.second[k0]) {
      ++end;
    }
    group.clear();
    int touching = 0;
    for (std::size_t g = e; g < end; ++g) {
      group.push_back(outcome(index(g)));
      touching += group.back().touching ? 1 : 0;
    }
    const double share = 1.0 / std::max(touching, 1);
    for (std::size_t g = e; g < end; ++g) {
      ContactOutcome& o = group[g - e];
      if (touching > 1) {
        o.force *= share;
        o.torque_first *= share;
        o.torque_second *= share;
      }
      use(index(g), o);
    }
    e = end;
  }
}

}  // namespace

void DemSimulation::compute_forces() {
  ParticleStore& p = setup_.particles;
  const double dt = setup_.time_step;
  const double now = time();

  const Vec3* x = p.position.data();
  const Vec3* v = p.velocity.data();
  const Vec3* w = p.angular_velocity.data();
  const double* rad = p.radius.data();
  const std::int32_t* mat = p.material.data();
  const Domain& domain = setup_.domain;
  const bool periodic = domain.periodic[0] || domain.periodic[1] || domain.periodic[2];

  // Sphere-sphere contacts, a batch at a time (sphere_pair_kernel.hpp).
  const SpherePairInputs sphere_pairs{x,
                                      v,
                                      w,
                                      rad,
                                      mat,
                                      setup_.contacts.data(),
                                      setup_.contacts.materials(),
                                      pairs_.first.data(),
                                      pairs_.second.data(),
                                      pairs_.history.data(),
                                      &domain,
                                      periodic,
                                      dt};

  // Sphere-obstacle contact k.
  const auto wall_outcome = [&](std::size_t k) __attribute__((always_inline)) {
    ContactOutcome out;
    const std::uint32_t i = walls_.first[k];
    const Obstacle& obstacle = setup_.obstacles[walls_.second[k]];
    ContactHistory& h = walls_.history[k];
    const SphereObstacleGap gap = obstacle.active(now) ? sphere_gap(obstacle, now, x[i], rad[i])
                                                       : SphereObstacleGap{-1.0, {}};
    if (gap.overlap < 0.0) {
      if (h.normal.x != 0.0 || h.normal.y != 0.0 || h.normal.z != 0.0) h = ContactHistory{};
      return out;
    }
    Vec3 arm_i;
    const ContactKinematics c =
        sphere_wall_kinematics(obstacle, now, x[i], v[i], w[i], rad[i], gap, arm_i);
    const ContactResponse r =
        evaluate_contact(setup_.contacts.get(static_cast<std::size_t>(mat[i]),
                                             static_cast<std::size_t>(obstacle.material)),
                         c, h, dt);
    out.force = r.force;
    out.torque_first = cross(arm_i, r.force) + r.rolling_torque;
    out.overlap_ratio = c.overlap / rad[i];
    out.touching = true;
    return out;
  };

  // Element contacts (bodies, or a body and a sphere): GJK on the cores (body_contacts.hpp).
  const auto& shapes = setup_.shapes;
  const auto size_of = [&](std::size_t i) {
    return p.spherical[i] ? rad[i]
                          : shapes[static_cast<std::size_t>(p.species[i])].equivalent_radius;
  };
  // An element contact that no longer touches forgets its memory (the twist is held only
  // while the history is, so it needs no test of its own).
  const auto forget = [](ContactHistory& h, double& twist) {
    if (h.normal.x != 0.0 || h.normal.y != 0.0 || h.normal.z != 0.0) {
      h = ContactHistory{};
      twist = 0.0;
    }
  };
  // The patch or point response of an element contact, on both bodies (body_contacts.hpp).
  const auto element_response =
      [&](std::size_t i, const ElementContact& ec, const geometry::ContactPatch* patch,
          const auto& other_velocity, const Vec3& other_omega, const Vec3* other_centre,
          const ContactParameters& params, ContactHistory& h, double& twist, ContactOutcome& out) {
        const ElementResponse r =
            element_contact_response(params, ec, patch, x[i], v[i], w[i], other_velocity,
                                     other_omega, other_centre, h, twist, dt);
        const Vec3 couple = r.response.rolling_torque + r.twist_torque;
        out.force = r.response.force;
        out.torque_first = cross(r.arm_first, r.response.force) + couple;
        out.torque_second = -(cross(r.arm_second, r.response.force) + couple);
        out.touching = true;
      };
  std::int64_t deep = 0;
  const bool mean = setup_.mean_element_contacts;
  const auto body_pair_outcome = [&](std::size_t k) {
    ContactOutcome out;
    const std::uint32_t i = body_pairs_.first[k], j = body_pairs_.second[k];
    ContactHistory& h = body_pairs_.history[k];
    Vec3 d = x[j] - x[i];
    if (periodic) d = domain.near_image(d);
    const Vec3 xj = x[i] + d;
    const ElementView a = element_view(p, shapes, i, body_pairs_.element_first[k], x[i]);
    const ElementView b = element_view(p, shapes, j, body_pairs_.element_second[k], xj);
    const double reach = a.reach + b.reach;
    if (norm2(b.position - a.position) > reach * reach) {  // bounding balls apart: no GJK
      forget(h, body_pairs_.twist[k]);
      return out;
    }
    const ElementContact ec =
        element_pair_contact(*a.core, {a.position, a.orientation}, a.crust, *b.core,
                             {b.position, b.orientation}, b.crust, &body_pairs_.warm[k]);
    if (!ec.touching) {
      forget(h, body_pairs_.twist[k]);
      return out;
    }
    // Built only for the patch model (the struct is 1 kB, zeroed when made).
    const auto patch = setup_.contact_patches
                           ? element_pair_patch(*a.core, {a.position, a.orientation}, a.crust,
                                                *b.core, {b.position, b.orientation}, b.crust, ec)
                           : std::nullopt;
    const auto vj = [&](const Vec3& point) { return v[j] + cross(w[j], point - xj); };
    element_response(
        i, ec, patch ? &*patch : nullptr, vj, w[j], &xj,
        setup_.contacts.get(static_cast<std::size_t>(mat[i]), static_cast<std::size_t>(mat[j])), h,
        body_pairs_.twist[k], out);
    out.overlap_ratio = ec.overlap / std::min(size_of(i), size_of(j));
    out.deep = ec.deep;
    return out;
  };
  const auto body_wall_outcome = [&](std::size_t k) {
    ContactOutcome out;
    const std::uint32_t i = body_walls_.first[k];
    const Obstacle& obstacle = setup_.obstacles[body_walls_.second[k]];
    ContactHistory& h = body_walls_.history[k];
    const ElementView a = element_view(p, shapes, i, body_walls_.element_first[k], x[i]);
    ElementContact ec;
    if (obstacle.active(now)) {
      ec = element_obstacle_contact(obstacle, body_walls_.element_second[k], now, *a.core,
                                    {a.position, a.orientation}, a.crust, &body_walls_.warm[k]);
    }
    if (!ec.touching) {
      forget(h, body_walls_.twist[k]);
      return out;
    }
    const auto patch =
        setup_.contact_patches
            ? element_obstacle_patch(obstacle, body_walls_.element_second[k], now, *a.core,
                                     {a.position, a.orientation}, a.crust, ec)
            : std::nullopt;
    const ObstacleMotion& m = obstacle.motion;
    const auto wall_velocity = [&](const Vec3& point) {
      return m.is_static() ? Vec3{} : m.velocity_at(now, point);
    };
    const Vec3 wall_omega = m.rotation.moving() ? m.rotation.speed_at(now) * m.axis : Vec3{};
    // The obstacle takes no torque: no centre, no lever arm.
    element_response(i, ec, patch ? &*patch : nullptr, wall_velocity, wall_omega, nullptr,
                     setup_.contacts.get(static_cast<std::size_t>(mat[i]),
                                         static_cast<std::size_t>(obstacle.material)),
                     h, body_walls_.twist[k], out);
    out.overlap_ratio = ec.overlap / size_of(i);
    out.deep = ec.deep;
    return out;
  };

  Vec3* f = p.force.data();
  Vec3* tq = p.torque.data();
  std::int32_t* coord = p.coordination.data();
  const std::size_t n_body_pairs = body_pairs_.size();
  const std::size_t n_body_walls = body_walls_.size();
  const std::size_t n_pairs = pairs_.size();
  const std::size_t n_walls = walls_.size();
  double worst = 0.0;
  std::int64_t touching_pairs = 0, touching_walls = 0;
  // A touching pair's outcome added to both particles.
  const auto add_to_both = [f, tq, coord](const ContactOutcome& o, std::uint32_t i,
                                          std::uint32_t j) {
    f[i] += o.force;
    f[j] -= o.force;
    tq[i] += o.torque_first;
    tq[j] += o.torque_second;
    ++coord[i];
    ++coord[j];
  };

  // Sphere pair k's outcome added to both spheres and to the tallies without a branch on
  // contact: a pair apart has +0 forces and torques and a zero overlap ratio
  // (evaluate_sphere_lanes), which leave the sums as they are, since they start at +0 and so
  // never hold the -0 that adding +0 would change. (Which listed pairs touch follows no
  // pattern the branch predictor learns: docs/performance.md.)
  const auto add_sphere_pair = [&](const ContactOutcome& o, std::size_t k, std::int64_t& touching,
                                   double& worst_ratio) {
    const std::uint32_t i = pairs_.first[k], j = pairs_.second[k];
    const std::int32_t on = o.touching ? 1 : 0;
    f[i] += o.force;
    f[j] -= o.force;
    tq[i] += o.torque_first;
    tq[j] += o.torque_second;
    coord[i] += on;
    coord[j] += on;
    touching += on;
    worst_ratio = std::max(worst_ratio, o.overlap_ratio);
  };

  if (threads_ <= 1) {
    // Serial: accumulate directly, contacts in list order.
    std::fill(p.force.begin(), p.force.end(), Vec3{});
    std::fill(p.torque.begin(), p.torque.end(), Vec3{});
    std::fill(p.coordination.begin(), p.coordination.end(), 0);
    const auto add_pair = [&](const ContactOutcome& o, std::uint32_t i, std::uint32_t j) {
      if (!o.touching) return;
      add_to_both(o, i, j);
      ++touching_pairs;
      deep += o.deep;
      worst = std::max(worst, o.overlap_ratio);
    };
    const auto add_wall = [&](const ContactOutcome& o, std::uint32_t i) {
      if (!o.touching) return;
      f[i] += o.force;
      tq[i] += o.torque_first;
      ++coord[i];
      ++touching_walls;
      deep += o.deep;
      worst = std::max(worst, o.overlap_ratio);
    };
    SpherePairLanes lanes;
    evaluate_sphere_pairs(
        sphere_pairs, [](std::size_t e) { return e; }, n_pairs, lanes,
        [&](std::size_t k, const ContactOutcome& o) {
          add_sphere_pair(o, k, touching_pairs, worst);
        });
    std::vector<ContactOutcome>& group = element_groups_[0];
    const auto in_order = [](std::size_t e) { return e; };
    element_contact_outcomes(body_pairs_, in_order, n_body_pairs, mean, group, body_pair_outcome,
                             [&](std::size_t k, const ContactOutcome& o) {
                               add_pair(o, body_pairs_.first[k], body_pairs_.second[k]);
                             });
    for (std::size_t k = 0; k < n_walls; ++k) add_wall(wall_outcome(k), walls_.first[k]);
    element_contact_outcomes(
        body_walls_, in_order, n_body_walls, mean, group, body_wall_outcome,
        [&](std::size_t k, const ContactOutcome& o) { add_wall(o, body_walls_.first[k]); });
  } else {
    // Threads: each block of particles (build_blocks) owns the contacts whose first
    // particle it holds. A particle whose contacts all lie in its block sums them there,
    // directly, in the order of the serial loop (sphere pairs, body pairs, sphere walls,
    // body walls, each in increasing contact index); only the contacts of shared
    // particles go through the outcome slots and the gather below. Bitwise the serial
    // result for any number of threads, no atomics, and only the contacts of shared
    // particles pass through memory twice. The sphere pairs are walked in runs
    // (build_pair_runs): long stretches of consecutive contacts between unshared
    // particles run the serial loop's code, without the per-contact tests below
    // (dem-spheres on 2 threads: about 5-10 % faster, docs/performance.md).
    const std::uint8_t* shared = shared_.data();
    const auto blocks = static_cast<std::ptrdiff_t>(block_pairs_.offset.size()) - 1;
    // One contact of a list: its outcome, kept for the gather when it touches a shared
    // particle, and added at once to the particles that are not shared.
    const auto pair_step = [&](const ContactOutcome& o, std::uint32_t i, std::uint32_t j,
                               std::uint8_t& touching_flag, ContactOutcome& slot) {
      if (shared[i] || shared[j]) {
        touching_flag = o.touching;
        if (o.touching) slot = o;
      }
      if (!o.touching) return;
      if (!shared[i]) {
        f[i] += o.force;
        tq[i] += o.torque_first;
        ++coord[i];
      }
      if (!shared[j]) {
        f[j] -= o.force;
        tq[j] += o.torque_second;
        ++coord[j];
      }
    };
    const auto wall_step = [&](const ContactOutcome& o, std::uint32_t i,
                               std::uint8_t& touching_flag, ContactOutcome& slot) {
      if (shared[i]) {
        touching_flag = o.touching;
        if (o.touching) slot = o;
      } else if (o.touching) {
        f[i] += o.force;
        tq[i] += o.torque_first;
        ++coord[i];
      }
    };
    const int nt = threads_;
#pragma omp parallel num_threads(nt)
    {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < p.size(); ++i) {
        if (shared[i]) continue;
        f[i] = Vec3{};
        tq[i] = Vec3{};
        coord[i] = 0;
      }
      // Slab b's contacts; the tallies are the calling thread's reduction copies.
      const auto run_slab = [&](std::size_t bu, double& slab_worst, std::int64_t& slab_pairs,
                                std::int64_t& slab_walls, std::int64_t& slab_deep) {
        const auto tally = [&](const ContactOutcome& o, std::int64_t& touching) {
          if (!o.touching) return;
          ++touching;
          slab_deep += o.deep;
          slab_worst = std::max(slab_worst, o.overlap_ratio);
        };
        const std::span<const std::uint32_t> block = block_pairs_.of(bu);
        SpherePairLanes lanes;
        for (std::uint32_t r = pair_run_offset_[bu]; r < pair_run_offset_[bu + 1]; ++r) {
          const PairRun run = pair_runs_[r];
          const std::size_t count = run.end - run.begin;
          if (run.direct) {  // consecutive contacts of unshared particles: as the serial loop
            const std::size_t k0 = block[run.begin];
            evaluate_sphere_pairs(
                sphere_pairs, [k0](std::size_t e) { return k0 + e; }, count, lanes,
                [&](std::size_t k, const ContactOutcome& o) {
                  add_sphere_pair(o, k, slab_pairs, slab_worst);
                });
          } else {
            const std::uint32_t* ks = block.data() + run.begin;
            evaluate_sphere_pairs(
                sphere_pairs, [ks](std::size_t e) { return std::size_t{ks[e]}; }, count, lanes,
                [&](std::size_t k, const ContactOutcome& o) {
                  tally(o, slab_pairs);
                  pair_step(o, pairs_.first[k], pairs_.second[k], pair_touching_[k],
                            pair_buffer_[k]);
                });
          }
        }
        std::vector<ContactOutcome>& group =
            element_groups_[static_cast<std::size_t>(omp_get_thread_num())];
        const std::span<const std::uint32_t> slab_body_pairs = block_body_pairs_.of(bu);
        element_contact_outcomes(
            body_pairs_, [&](std::size_t e) { return std::size_t{slab_body_pairs[e]}; },
            slab_body_pairs.size(), mean, group, body_pair_outcome,
            [&](std::size_t k, const ContactOutcome& o) {
              tally(o, slab_pairs);
              pair_step(o, body_pairs_.first[k], body_pairs_.second[k], body_pair_touching_[k],
                        body_pair_buffer_[k]);
            });
        for (const std::uint32_t k : block_walls_.of(bu)) {
          const ContactOutcome o = wall_outcome(k);
          tally(o, slab_walls);
          wall_step(o, walls_.first[k], wall_touching_[k], wall_buffer_[k]);
        }
        const std::span<const std::uint32_t> slab_body_walls = block_body_walls_.of(bu);
        element_contact_outcomes(
            body_walls_, [&](std::size_t e) { return std::size_t{slab_body_walls[e]}; },
            slab_body_walls.size(), mean, group, body_wall_outcome,
            [&](std::size_t k, const ContactOutcome& o) {
              tally(o, slab_walls);
              wall_step(o, body_walls_.first[k], body_wall_touching_[k], body_wall_buffer_[k]);
            });
      };
      if (blocks > nt) {
        // Several slabs per thread (bodies, build_blocks): each thread walks its own run
        // of neighbouring slabs in order, then takes the last slab of the thread with the
        // most left. Each keeps to its own stretch of space and memory, as with one slab
        // per thread, while the cut between the threads moves with the actual cost.
        const int team = omp_get_num_threads();
#pragma omp single
        slab_queue_.start(blocks, team);
        // Iteration t of the loop runs on thread t (static, 1 over the team).
#pragma omp for schedule(static, 1) reduction(max : worst) \
    reduction(+ : touching_pairs, touching_walls, deep)
        for (int me = 0; me < team; ++me) {
          for (;;) {
            std::ptrdiff_t b = -1;
#pragma omp critical(sanguis_dem_slab_queue)
            b = slab_queue_.take(me);
            if (b < 0) break;
            run_slab(static_cast<std::size_t>(b), worst, touching_pairs, touching_walls, deep);
          }
        }
      } else {
        // One slab per thread, thread t slab t: the particles its integrator loop holds.
#pragma omp for schedule(static, 1) reduction(max : worst) \
    reduction(+ : touching_pairs, touching_walls, deep)
        for (std::ptrdiff_t b = 0; b < blocks; ++b) {
          run_slab(static_cast<std::size_t>(b), worst, touching_pairs, touching_walls, deep);
        }
      }
#pragma omp for schedule(static)
      for (std::size_t s = 0; s < shared_list_.size(); ++s) {
        const std::uint32_t i = shared_list_[s];
        Vec3 force{}, torque{};
        std::int32_t count = 0;
        const auto add_pairs = [&](const std::vector<std::uint32_t>& offset,
                                   const std::vector<std::uint32_t>& entries,
                                   const std::vector<ContactOutcome>& outcomes,
                                   const std::vector<std::uint8_t>& touching) {
          for (std::uint32_t e = offset[i]; e < offset[i + 1]; ++e) {
            if (!touching[entries[e] >> 1]) continue;
            const ContactOutcome& o = outcomes[entries[e] >> 1];
            if ((entries[e] & 1u) == 0) {
              force += o.force;
              torque += o.torque_first;
            } else {
              force -= o.force;
              torque += o.torque_second;
            }
            ++count;
          }
        };
        const auto add_walls = [&](const std::vector<std::uint32_t>& offset,
                                   const std::vector<ContactOutcome>& outcomes,
                                   const std::vector<std::uint8_t>& touching) {
          for (std::uint32_t k = offset[i]; k < offset[i + 1]; ++k) {
            if (!touching[k]) continue;
            force += outcomes[k].force;
            torque += outcomes[k].torque_first;
            ++count;
          }
        };
        add_pairs(incident_offset_, incident_, pair_buffer_, pair_touching_);
        if (has_bodies_) {
          add_pairs(body_incident_offset_, body_incident_, body_pair_buffer_, body_pair_touching_);
        }
        add_walls(wall_offset_, wall_buffer_, wall_touching_);
        if (has_bodies_) add_walls(body_wall_offset_, body_wall_buffer_, body_wall_touching_);
        f[i] = force;
        tq[i] = torque;
        coord[i] = count;
      }
    }
  }
  touching_pairs_ = touching_pairs;
  touching_walls_ = touching_walls;
  max_overlap_ratio_ = worst;
  deep_contacts_ = deep;

  if (!(worst <= setup_.max_overlap_ratio)) {
    std::ostringstream msg;
    msg << "step " << step_ << " (t = " << now << " s): overlap of " << worst
        << " x radius exceeds the bound " << setup_.max_overlap_ratio
        << "; the time step is too large for the contact stiffness, or particles were "
           "created overlapping";
    throw SimulationError(msg.str());
  }
}

void DemSimulation::choose_threads() {
  // Threads pay off only with enough work per thread between two barriers; below that the
  // serial path is used (same results, bit for bit), which also keeps small runs from
  // stalling when the cores are shared. Chosen again at every rebuild: a pour that starts
  // empty takes the threads once it holds enough particles.
  const std::size_t per_thread =
      setup_.particles_per_thread > 0 ? setup_.particles_per_thread : (has_bodies_ ? 500 : 4000);
  const auto useful =
      static_cast<int>(std::max<std::size_t>(1, setup_.particles.size() / per_thread));
  threads_ = std::clamp(setup_.threads, 1, useful);
  integrator_.set_threads(threads_);
}

void DemSimulation::rebuild_lists() {
  choose_threads();
  search_.rebuild(setup_.particles, setup_.obstacles, time(), pairs_, walls_,
                  ghost_.empty() ? nullptr : ghost_.data(), threads_);
  if (has_bodies_) split_body_contacts();
  build_incidence();
}

bool DemSimulation::sort_due() const {
  const std::int64_t interval = setup_.storage_sort_interval;
  if (interval <= 0) return false;
  // When the simulation is built, then at fixed steps (with a list rebuild there): a
  // schedule that does not depend on when the lists happen to be rebuilt, which differs
  // after a restart, so that a restarted run sorts where the first run did.
  return search_.rebuild_count() == 0 || step_ % interval == 0;
}

void DemSimulation::assign_sort_keys() {
  if (setup_.storage_sort_interval > 0) compute_sort_keys();
}

void DemSimulation::compute_sort_keys() {
  ParticleStore& p = setup_.particles;
  // The extent of the owned particles, wrapped, over every process: each computes the
  // keys one process would.
  Extent extent = Extent::empty_in(setup_.domain.min, setup_.domain.max);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (is_ghost(i)) continue;
    Vec3 x = p.position[i];
    setup_.domain.wrap(x);
    extent.add(x);
  }
  if (exchange_ != nullptr) exchange_->bounds(extent.low, extent.high);
  p.sort_key = search_.space_keys(p, extent.longest_axis());
}

void DemSimulation::sort_storage() {
  if (exchange_ != nullptr) {
    throw std::logic_error("sort_storage: a process of a decomposed run sorts as it exchanges");
  }
  rebuild_sorted();  // the forces stay valid: they moved with their particles
}

// New keys, the storage sorted by (key, id), the lists renumbered (pairs turned round
// where the new order puts the other particle first) and rebuilt: what a decomposed run
// does when it exchanges its particles with their memories, in one process.
void DemSimulation::rebuild_sorted() {
  ParticleStore& p = setup_.particles;
  compute_sort_keys();
  std::vector<std::uint32_t> order(p.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return stored_before(p.sort_key[a], p.id[a], p.sort_key[b], p.id[b]);
  });
  p.permute(order);
  integrator_.permute(order);
  apply_order(ghost_, order);
  std::vector<std::uint32_t> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    new_index[order[k]] = static_cast<std::uint32_t>(k);
  renumber(pairs_, new_index, true);
  renumber(walls_, new_index, false);
  renumber(body_pairs_, new_index, true);
  renumber(body_walls_, new_index, false);
  rebuild_lists();
}

// Moves the candidate pairs that involve a non-spherical body from the sphere lists to
// the element lists (one entry per pair of elements whose bounding balls are within the
// skin), carrying the element histories over.
void DemSimulation::split_body_contacts() {
  const ParticleStore& p = setup_.particles;
  const auto& shapes = setup_.shapes;
  const double skin = search_.skin();
  const double now = time();
  const Domain& domain = setup_.domain;

  // Space-frame boxes of every element, grown by its crust and half the skin: two elements
  // whose boxes are apart cannot touch before the next rebuild (each moves < skin / 2).
  const std::size_t n = p.size();
  std::vector<std::uint32_t> first_box(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    first_box[i + 1] = first_box[i] + static_cast<std::uint32_t>(element_count(p, shapes, i));
  }
  std::vector<geometry::Aabb> boxes(first_box[n]);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t e = 0; e < element_count(p, shapes, i); ++e) {
      const ElementView a = element_view(p, shapes, i, e, p.position[i]);
      geometry::Aabb b = p.spherical[i] ? geometry::Aabb{a.position, a.position}
                                        : geometry::bounds(*a.core, a.position, a.orientation);
      const Vec3 grow{a.crust + 0.5 * skin, a.crust + 0.5 * skin, a.crust + 0.5 * skin};
      boxes[first_box[i] + e] = {b.min - grow, b.max + grow};
    }
  }
  const auto boxes_meet = [&](const geometry::Aabb& a, geometry::Aabb b, const Vec3& shift) {
    b.min += shift;
    b.max += shift;
    return a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
           a.min.z <= b.max.z && b.min.z <= a.max.z;
  };

  // Two box elements (the arms of crosses) whose axis-aligned boxes meet are often far
  // apart when tilted: keep the pair only if no separating axis puts their cores more
  // than both crusts and the skin apart (each point moves < skin / 2 before the next
  // rebuild, so such a pair cannot touch before then).
  const auto arms_apart = [&](std::size_t i, std::size_t ea, std::size_t j, std::size_t eb,
                              const Vec3& shift) {
    const ElementView a = element_view(p, shapes, i, ea, p.position[i]);
    const ElementView b = element_view(p, shapes, j, eb, p.position[j] + shift);
    const auto* box_a = std::get_if<geometry::Box>(a.core);
    const auto* box_b = std::get_if<geometry::Box>(b.core);
    return box_a && box_b &&
           geometry::boxes_apart_beyond(*box_a, {a.position, a.orientation}, *box_b,
                                        {b.position, b.orientation}, a.crust + b.crust + skin);
  };
  ContactList spheres_only;
  BodyContactList fresh;
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    const std::uint32_t i = pairs_.first[k], j = pairs_.second[k];
    if (p.spherical[i] && p.spherical[j]) {
      spheres_only.push(i, j, pairs_.history[k]);
      continue;
    }
    // Periodic image of j next to i.
    const Vec3 shift =
        domain.minimum_image(p.position[j] - p.position[i]) - (p.position[j] - p.position[i]);
    for (std::size_t ea = 0; ea < element_count(p, shapes, i); ++ea) {
      for (std::size_t eb = 0; eb < element_count(p, shapes, j); ++eb) {
        if (!boxes_meet(boxes[first_box[i] + ea], boxes[first_box[j] + eb], shift)) continue;
        if (arms_apart(i, ea, j, eb, shift)) continue;
        fresh.push(i, j, static_cast<std::uint16_t>(ea), static_cast<std::uint16_t>(eb));
      }
    }
  }
  pairs_ = std::move(spheres_only);
  carry_history(body_pairs_, fresh);
  body_pairs_ = std::move(fresh);

  ContactList sphere_walls;
  BodyContactList fresh_walls;
  for (std::size_t k = 0; k < walls_.size(); ++k) {
    const std::uint32_t i = walls_.first[k], o = walls_.second[k];
    const Obstacle& obstacle = setup_.obstacles[o];
    const auto* shaped = std::get_if<ShapeObstacle>(&obstacle.shape);
    if (p.spherical[i] && shaped == nullptr) {
      sphere_walls.push(i, o, walls_.history[k]);
      continue;
    }
    for (std::size_t ea = 0; ea < element_count(p, shapes, i); ++ea) {
      const ElementView a = element_view(p, shapes, i, ea, p.position[i]);
      if (shaped == nullptr) {
        if (sphere_gap(obstacle, now, a.position, a.reach).overlap > -skin) {
          fresh_walls.push(i, o, static_cast<std::uint16_t>(ea), 0);
        }
        continue;
      }
      // Each obstacle element near the particle element is its own contact.
      const geometry::Aabb& box_a = boxes[first_box[i] + ea];
      for (std::size_t eb = 0; eb < shaped->elements.size(); ++eb) {
        const ObstacleElement& e = shaped->elements[eb];
        const geometry::Aabb b =
            geometry::bounds(e.shape, obstacle.motion.point_at(now, e.position),
                             obstacle.motion.rotation_at(now) * e.orientation);
        if (boxes_meet(box_a, b, Vec3{})) {
          fresh_walls.push(i, o, static_cast<std::uint16_t>(ea), static_cast<std::uint16_t>(eb));
        }
      }
    }
  }
  walls_ = std::move(sphere_walls);
  carry_history(body_walls_, fresh_walls);
  body_walls_ = std::move(fresh_walls);
}

namespace {

// For each particle, the contacts of a pair list it takes part in, in increasing contact
// index (bit 0 of an entry: the particle is the pair's second body); CSR layout.
void pair_incidence(const std::vector<std::uint32_t>& first,
                    const std::vector<std::uint32_t>& second, std::size_t n,
                    std::vector<std::uint32_t>& offset, std::vector<std::uint32_t>& entries,
                    std::vector<std::uint32_t>& fill) {
  offset.assign(n + 1, 0);
  for (std::size_t k = 0; k < first.size(); ++k) {
    ++offset[first[k] + 1];
    ++offset[second[k] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
  entries.resize(offset[n]);
  fill.assign(offset.begin(), offset.end() - 1);
  for (std::size_t k = 0; k < first.size(); ++k) {
    const auto entry = static_cast<std::uint32_t>(k << 1);
    entries[fill[first[k]]++] = entry;
    entries[fill[second[k]]++] = entry | 1u;
  }
}

// For a list sorted by particle (walls), each particle's range of entries.
void particle_ranges(const std::vector<std::uint32_t>& first, std::size_t n,
                     std::vector<std::uint32_t>& offset) {
  offset.assign(n + 1, 0);
  for (std::uint32_t i : first) ++offset[i + 1];
  for (std::size_t i = 0; i < n; ++i) offset[i + 1] += offset[i];
}

}  // namespace

void DemSimulation::build_incidence() {
  // One group buffer per thread (compute_forces); empty unless the mean is asked for.
  element_groups_.resize(static_cast<std::size_t>(std::max(threads_, 1)));
  if (setup_.mean_element_contacts) {
    // Room for the longest group of one pair of bodies' element contacts (compute_forces).
    std::size_t longest = 0;
    for (const BodyContactList* list : {&body_pairs_, &body_walls_}) {
      for (std::size_t k = 0, run = 0; k < list->size(); ++k) {
        const bool same =
            k > 0 && list->first[k] == list->first[k - 1] && list->second[k] == list->second[k - 1];
        run = same ? run + 1 : 1;
        longest = std::max(longest, run);
      }
    }
    for (std::vector<ContactOutcome>& group : element_groups_) group.reserve(longest);
  }
  if (threads_ <= 1) {
    pair_runs_.clear();  // the serial loop needs no slabs
    return;
  }
  // What the threaded gather reads (see compute_forces).
  const std::size_t n = setup_.particles.size();
  pair_incidence(pairs_.first, pairs_.second, n, incident_offset_, incident_, incident_fill_);
  particle_ranges(walls_.first, n, wall_offset_);
  pair_incidence(body_pairs_.first, body_pairs_.second, n, body_incident_offset_, body_incident_,
                 incident_fill_);
  particle_ranges(body_walls_.first, n, body_wall_offset_);
  pair_buffer_.resize(pairs_.size());
  wall_buffer_.resize(walls_.size());
  body_pair_buffer_.resize(body_pairs_.size());
  body_wall_buffer_.resize(body_walls_.size());
  pair_touching_.resize(pairs_.size());
  wall_touching_.resize(walls_.size());
  body_pair_touching_.resize(body_pairs_.size());
  body_wall_touching_.resize(body_walls_.size());
  build_blocks();
}

// Cuts space into one slab per thread (up to kBodySlabsPerThread with bodies) along the
// longest axis of the particles, with about equal work in each (a contact belongs to the
// slab of its first particle; an element pair weighs as kElementPairWeight sphere
// contacts, for its GJK), lists each slab's contacts in increasing index, and marks the
// particles with a pair in another slab as shared. Slabs, not index ranges: between two
// storage sorts the particles move away from their place in memory (and with the sort
// off, storage follows creation order).
void DemSimulation::build_blocks() {
  constexpr std::uint32_t kElementPairWeight = 8;
  constexpr std::size_t kBins = 4096;
  const ParticleStore& p = setup_.particles;
  const std::size_t n = p.size();
  Extent extent = Extent::empty_in(setup_.domain.min, setup_.domain.max);
  for (const Vec3& x : p.position) extent.add(x);
  const int axis = extent.longest_axis();
  const double lo = extent.low[axis], span = std::max(extent.high[axis] - lo, 1e-300);
  std::vector<std::uint32_t> bin(n);
  for (std::size_t i = 0; i < n; ++i) {
    bin[i] = static_cast<std::uint32_t>(axis_bin(p.position[i][axis], lo, span, kBins));
  }
  std::vector<std::uint64_t> work(kBins, 0);
  for (std::uint32_t i : pairs_.first) ++work[bin[i]];
  for (std::uint32_t i : walls_.first) ++work[bin[i]];
  for (std::uint32_t i : body_pairs_.first) work[bin[i]] += kElementPairWeight;
  for (std::uint32_t i : body_walls_.first) ++work[bin[i]];

  // The most slabs per thread (kBodySlabsPerThread with bodies, halved as needed) that
  // leave at most setup_.most_shared_fraction of the particles shared.
  std::vector<std::uint32_t> block(n), block_of_bin(kBins);
  std::size_t blocks = 0;
  const auto mark = [&](const std::vector<std::uint32_t>& first,
                        const std::vector<std::uint32_t>& second) {
    for (std::size_t c = 0; c < first.size(); ++c) {
      if (block[first[c]] != block[second[c]]) shared_[first[c]] = shared_[second[c]] = 1;
    }
  };
  for (std::size_t per_thread = has_bodies_ ? kBodySlabsPerThread : 1;; per_thread /= 2) {
    blocks = static_cast<std::size_t>(threads_) * per_thread;
    const std::vector<std::size_t> cut = equal_weight_cuts(work, blocks);
    for (std::size_t b = 0; b < blocks; ++b) {
      for (std::size_t k = cut[b]; k < cut[b + 1]; ++k)
        block_of_bin[k] = static_cast<std::uint32_t>(b);
    }
    for (std::size_t i = 0; i < n; ++i) block[i] = block_of_bin[bin[i]];
    shared_.assign(n, 0);
    mark(pairs_.first, pairs_.second);
    mark(body_pairs_.first, body_pairs_.second);
    const auto shared = static_cast<double>(std::count(shared_.begin(), shared_.end(), 1));
    if (per_thread == 1 || shared <= setup_.most_shared_fraction * static_cast<double>(n)) break;
  }

  block_pairs_.build(pairs_.first, block, blocks);
  block_walls_.build(walls_.first, block, blocks);
  block_body_pairs_.build(body_pairs_.first, block, blocks);
  block_body_walls_.build(body_walls_.first, block, blocks);
  shared_list_.clear();
  for (std::uint32_t i = 0; i < n; ++i) {
    if (shared_[i]) shared_list_.push_back(i);
  }
  build_pair_runs();
}

void DemSimulation::build_pair_runs() {
  // Shorter direct stretches stay in the general runs: a run costs a call and a partly
  // filled batch of lanes (SpherePairLanes::kLanes).
  constexpr std::uint32_t kShortestDirectRun = 2 * SpherePairLanes::kLanes;
  const std::size_t blocks = block_pairs_.offset.size() - 1;
  const auto direct = [this](std::uint32_t k) {
    return !shared_[pairs_.first[k]] && !shared_[pairs_.second[k]];
  };
  pair_runs_.clear();
  pair_run_offset_.assign(blocks + 1, 0);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::span<const std::uint32_t> list = block_pairs_.of(b);
    const auto n = static_cast<std::uint32_t>(list.size());
    std::uint32_t general_begin = 0;
    bool general_open = false;
    std::uint32_t e = 0;
    while (e < n) {
      std::uint32_t end = e;  // the longest direct stretch from e
      while (end < n && direct(list[end]) && (end == e || list[end] == list[end - 1] + 1)) ++end;
      if (end - e >= kShortestDirectRun) {
        if (general_open) pair_runs_.push_back({general_begin, e, false});
        general_open = false;
        pair_runs_.push_back({e, end, true});
        e = end;
      } else {
        if (!general_open) general_begin = e;
        general_open = true;
        e = std::max(end, e + 1);
      }
    }
    if (general_open) pair_runs_.push_back({general_begin, n, false});
    pair_run_offset_[b + 1] = static_cast<std::uint32_t>(pair_runs_.size());
  }
}

void SlabQueue::start(std::ptrdiff_t slabs, int threads) {
  next.resize(static_cast<std::size_t>(threads));
  end.resize(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) {
    next[static_cast<std::size_t>(t)] = slabs * t / threads;
    end[static_cast<std::size_t>(t)] = slabs * (t + 1) / threads;
  }
}

std::ptrdiff_t SlabQueue::take(int thread) {
  const auto me = static_cast<std::size_t>(thread);
  if (next[me] < end[me]) return next[me]++;
  std::size_t most = 0;
  for (std::size_t t = 1; t < next.size(); ++t) {
    if (end[t] - next[t] > end[most] - next[most]) most = t;
  }
  return next[most] < end[most] ? --end[most] : -1;
}

void BlockContacts::build(const std::vector<std::uint32_t>& first,
                          const std::vector<std::uint32_t>& block, std::size_t blocks) {
  offset.assign(blocks + 1, 0);
  for (std::uint32_t i : first) ++offset[block[i] + 1];
  for (std::size_t b = 0; b < blocks; ++b) offset[b + 1] += offset[b];
  index.resize(first.size());
  fill.assign(offset.begin(), offset.end() - 1);
  for (std::size_t k = 0; k < first.size(); ++k) {
    index[fill[block[first[k]]]++] = static_cast<std::uint32_t>(k);
  }
}

void DemSimulation::check_state() const {
  const ParticleStore& p = setup_.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& x = p.position[i];
    const Vec3& v = p.velocity[i];
    if (!std::isfinite(x.x + x.y + x.z + v.x + v.y + v.z)) {
      std::ostringstream msg;
      msg << "step " << step_ << " (t = " << time() << " s): particle " << p.id[i]
          << " has a non-finite position or velocity (numerical blow-up)";
      throw SimulationError(msg.str());
    }
  }
}

DemDiagnostics DemSimulation::diagnostics() const {
  const ParticleStore& p = setup_.particles;
  DemDiagnostics d;
  d.time = time();
  std::size_t owned = 0;
  for (const std::uint32_t i : id_order(p.id)) {  // sums in id order: any storage order
    if (is_ghost(i) || p.is_fixed(i)) continue;
    ++owned;
    const double v2 = norm2(p.velocity[i]);
    const double w2 = norm2(p.angular_velocity[i]);
    d.kinetic_energy_translational += 0.5 * p.mass[i] * v2;
    const Vec3 wb = rotate_inverse(p.orientation[i], p.angular_velocity[i]);
    const Vec3& j = p.inertia_body[i];
    d.kinetic_energy_rotational +=
        0.5 * (j.x * wb.x * wb.x + j.y * wb.y * wb.y + j.z * wb.z * wb.z);
    const double speed = std::sqrt(v2);
    d.mean_velocity += speed;
    d.max_velocity = std::max(d.max_velocity, speed);
    d.mean_angular_velocity += std::sqrt(w2);
  }
  d.mobile_particles = static_cast<std::int64_t>(owned);
  if (owned > 0) {
    d.mean_velocity /= static_cast<double>(owned);
    d.mean_angular_velocity /= static_cast<double>(owned);
  }
  d.particle_contacts = touching_pairs_;
  d.wall_contacts = touching_walls_;
  d.max_overlap_ratio = max_overlap_ratio_;
  d.deep_contacts = deep_contacts_;
  if (!ghost_.empty()) {
    // A pair with a ghost is evaluated by both processes: count it where its first (smaller
    // id) particle is owned. A contact touched at the last evaluation keeps its normal.
    const auto touching = [](const ContactHistory& h) {
      return h.normal.x != 0.0 || h.normal.y != 0.0 || h.normal.z != 0.0;
    };
    d.particle_contacts = 0;
    for (std::size_t k = 0; k < pairs_.size(); ++k) {
      d.particle_contacts += !is_ghost(pairs_.first[k]) && touching(pairs_.history[k]);
    }
    for (std::size_t k = 0; k < body_pairs_.size(); ++k) {
      d.particle_contacts += !is_ghost(body_pairs_.first[k]) && touching(body_pairs_.history[k]);
    }
  }
  return d;
}

// ---------------------------------------------------------------- domain decomposition

std::size_t DemSimulation::owned_count() const {
  if (ghost_.empty()) return setup_.particles.size();
  return static_cast<std::size_t>(std::count(ghost_.begin(), ghost_.end(), std::uint8_t{0}));
}

namespace {

// Contact k of a list as an id-keyed memory slot (history not copied): walls keep the
// obstacle index, body lists their element numbers.
template <typename List>
ContactMemory memory_key(const List& list, std::size_t k, std::uint8_t kind, bool wall,
                         const std::vector<std::int64_t>& id) {
  ContactMemory m;
  m.kind = kind;
  m.first_id = id[list.first[k]];
  m.second_id = wall ? std::int64_t{list.second[k]} : id[list.second[k]];
  if constexpr (std::is_same_v<List, BodyContactList>) {
    m.element_first = list.element_first[k];
    m.element_second = list.element_second[k];
  }
  return m;
}

}  // namespace

std::vector<ContactMemory> DemSimulation::export_contacts() const {
  const std::vector<std::int64_t>& id = setup_.particles.id;
  std::vector<ContactMemory> out;
  out.reserve(pairs_.size() + walls_.size() + body_pairs_.size() + body_walls_.size());
  const auto add = [&](const auto& list, std::uint8_t kind, bool wall) {
    for (std::size_t k = 0; k < list.size(); ++k) {
      ContactMemory m = memory_key(list, k, kind, wall, id);
      m.history = list.history[k];
      if constexpr (std::is_same_v<std::decay_t<decltype(list)>, BodyContactList>) {
        m.warm = list.warm[k];
        m.twist = list.twist[k];
      }
      out.push_back(m);
    }
  };
  add(pairs_, ContactMemory::kSpherePair, false);
  add(walls_, ContactMemory::kSphereWall, true);
  add(body_pairs_, ContactMemory::kBodyPair, false);
  add(body_walls_, ContactMemory::kBodyWall, true);
  return out;
}

void DemSimulation::import_contacts(std::span<const ContactMemory> contacts) {
  const std::vector<std::int64_t>& id = setup_.particles.id;
  const auto fill = [&](auto& list, std::uint8_t kind, bool wall) {
    for (std::size_t k = 0; k < list.size(); ++k) {
      const ContactMemory probe = memory_key(list, k, kind, wall, id);
      const auto it = std::lower_bound(
          contacts.begin(), contacts.end(), probe,
          [](const ContactMemory& a, const ContactMemory& b) { return a.key() < b.key(); });
      if (it == contacts.end() || it->key() != probe.key()) continue;
      const ContactMemory m = it->as_oriented(probe.first_id);
      list.history[k] = m.history;
      if constexpr (std::is_same_v<std::decay_t<decltype(list)>, BodyContactList>) {
        list.warm[k] = m.warm;
        list.twist[k] = m.twist;
      }
    }
  };
  fill(pairs_, ContactMemory::kSpherePair, false);
  fill(walls_, ContactMemory::kSphereWall, true);
  fill(body_pairs_, ContactMemory::kBodyPair, false);
  fill(body_walls_, ContactMemory::kBodyWall, true);
}

void DemSimulation::replace_particles(ParticleStore particles, std::vector<std::uint8_t> ghost,
                                      std::vector<Vec3> half_velocity,
                                      std::vector<Vec3> half_angular,
                                      std::span<const ContactMemory> contacts) {
  const std::size_t n = particles.size();
  if (ghost.size() != n || half_velocity.size() != n || half_angular.size() != n) {
    throw std::invalid_argument("replace_particles: per-particle arrays differ in size");
  }
  for (std::size_t i = 1; i < n; ++i) {
    // Pairs are oriented by local index; the (sort key, id) order orients them as one
    // process would.
    const auto& key = particles.sort_key;
    if (!stored_before(key[i - 1], particles.id[i - 1], key[i], particles.id[i])) {
      throw std::invalid_argument(
          "replace_particles: particles not in increasing (sort key, id) order");
    }
  }
  setup_.particles = std::move(particles);
  ghost_ = std::move(ghost);
  // Bodies may arrive on a process that started with spheres only.
  for (std::uint8_t spherical : setup_.particles.spherical) has_bodies_ |= spherical == 0;
  integrator_.half_velocity() = std::move(half_velocity);
  integrator_.half_angular_velocity() = std::move(half_angular);
  pairs_.clear();
  walls_.clear();
  body_pairs_.clear();
  body_walls_.clear();
  rebuild_lists();
  import_contacts(contacts);
}

// ---------------------------------------------------------------- checkpoints

namespace {

constexpr char kMagic[16] = "SANGUIS-DEM-CK4";
// The twist memory of body contacts as an angle (until 2026-12-05): read and dropped,
// since a moment cannot be formed from it without the patch; the moments start at zero.
constexpr char kMagicWithTwistAngles[16] = "SANGUIS-DEM-CK3";
// Before the contact patches: no twist memory on body contacts (read as zero twist).
constexpr char kMagicWithoutTwist[16] = "SANGUIS-DEM-CK2";
// Before the storage sort: no sort keys (particles in the order of their creation), no
// twist.
constexpr char kMagicWithoutSortKeys[16] = "SANGUIS-DEM-CK1";

template <typename T>
void put(std::ostream& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void put(std::ostream& out, const std::vector<T>& values) {
  static_assert(std::is_trivially_copyable_v<T>);
  put<std::uint64_t>(out, values.size());
  out.write(reinterpret_cast<const char*>(values.data()),
            static_cast<std::streamsize>(values.size() * sizeof(T)));
}

template <typename T>
void get(std::istream& in, T& value) {
  in.read(reinterpret_cast<char*>(&value), sizeof(T));
  if (!in) throw std::runtime_error("checkpoint is truncated");
}

template <typename T>
void get(std::istream& in, std::vector<T>& values) {
  std::uint64_t n = 0;
  get(in, n);
  if (n > (std::uint64_t{1} << 40)) throw std::runtime_error("checkpoint is corrupt");
  values.resize(n);
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(n * sizeof(T)));
  if (!in) throw std::runtime_error("checkpoint is truncated");
}

void put_list(std::ostream& out, const ContactList& list) {
  put(out, list.first);
  put(out, list.second);
  put(out, list.history);
}

void get_list(std::istream& in, ContactList& list) {
  get(in, list.first);
  get(in, list.second);
  get(in, list.history);
  if (list.second.size() != list.first.size() || list.history.size() != list.first.size()) {
    throw std::runtime_error("checkpoint contact list is inconsistent");
  }
}

void put_body_list(std::ostream& out, const BodyContactList& list) {
  put(out, list.first);
  put(out, list.second);
  put(out, list.element_first);
  put(out, list.element_second);
  put(out, list.history);
  put(out, list.warm);
}

// The twists come last in the file (load_checkpoint reads them there); zero until then.
void get_body_list(std::istream& in, BodyContactList& list) {
  get(in, list.first);
  get(in, list.second);
  get(in, list.element_first);
  get(in, list.element_second);
  get(in, list.history);
  get(in, list.warm);
  for (geometry::GjkWarmStart& w : list.warm) w.unused = 0;  // an older file's padding
  list.twist.assign(list.first.size(), 0.0);
  const std::size_t n = list.first.size();
  if (list.second.size() != n || list.element_first.size() != n ||
      list.element_second.size() != n || list.history.size() != n || list.warm.size() != n) {
    throw std::runtime_error("checkpoint contact list is inconsistent");
  }
}

template <typename F>
void for_each_particle_array(ParticleStore& p, F&& f) {
  f(p.id);
  f(p.material);
  f(p.radius);
  f(p.mass);
  f(p.inverse_mass);
  f(p.species);
  f(p.spherical);
  f(p.inertia_body);
  f(p.inverse_inertia_body);
  f(p.orientation);
  f(p.position);
  f(p.velocity);
  f(p.angular_velocity);
  f(p.force);
  f(p.torque);
  f(p.coordination);
}

}  // namespace

void DemSimulation::save_checkpoint(const std::filesystem::path& file) const {
  io::write_file_atomically(file, [&](std::ostream& out) {
    out.write(kMagic, sizeof(kMagic));
    put(out, setup_.time_step);
    put(out, static_cast<std::int32_t>(setup_.integrator));
    put(out, step_);
    auto& p = const_cast<ParticleStore&>(setup_.particles);
    for_each_particle_array(p, [&](auto& array) { put(out, array); });
    const MultistepHistory& h = integrator_.history();
    put(out, static_cast<std::int32_t>(h.depth));
    for (int k = 0; k < 2; ++k) {
      put(out, h.velocity[k]);
      put(out, h.acceleration[k]);
      put(out, h.angular_velocity[k]);
      put(out, h.angular_acceleration[k]);
    }
    auto& search = const_cast<NeighborSearch&>(search_);
    put(out, search.reference_positions());
    put(out, search.rebuild_counter());
    put(out, search.reference_time());
    put_list(out, pairs_);
    put_list(out, walls_);
    put(out, search.reference_orientations());
    put_body_list(out, body_pairs_);
    put_body_list(out, body_walls_);
    for (const PourSource& src : setup_.pour) put(out, src.inserted);
    std::ostringstream rng;
    rng << pour_rng_;
    const std::string rng_state = rng.str();
    put(out, std::vector<char>(rng_state.begin(), rng_state.end()));
    put(out, max_overlap_ratio_);
    put(out, touching_pairs_);
    put(out, touching_walls_);
    put(out, setup_.particles.sort_key);
    // Last, so that a file of an older format is this one cut short.
    put(out, body_pairs_.twist);
    put(out, body_walls_.twist);
  });
}

void DemSimulation::load_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open checkpoint");
  try {
    char magic[sizeof(kMagic)] = {};
    in.read(magic, sizeof(magic));
    const bool without_keys =
        in && std::memcmp(magic, kMagicWithoutSortKeys, sizeof(kMagicWithoutSortKeys)) == 0;
    const bool without_twist = without_keys || (in && std::memcmp(magic, kMagicWithoutTwist,
                                                                  sizeof(kMagicWithoutTwist)) == 0);
    const bool twist_angles =
        in && std::memcmp(magic, kMagicWithTwistAngles, sizeof(kMagicWithTwistAngles)) == 0;
    if (!in ||
        (!without_twist && !twist_angles && std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)) {
      throw std::runtime_error("not a sanguis DEM checkpoint");
    }
    double dt = 0.0;
    std::int32_t kind = 0;
    get(in, dt);
    get(in, kind);
    if (dt != setup_.time_step || kind != static_cast<std::int32_t>(setup_.integrator)) {
      throw std::runtime_error(
          "checkpoint was written with another time step or integrator than this case");
    }
    get(in, step_);
    for_each_particle_array(setup_.particles, [&](auto& array) { get(in, array); });
    MultistepHistory& h = integrator_.history();
    std::int32_t depth = 0;
    get(in, depth);
    h.depth = depth;
    for (int k = 0; k < 2; ++k) {
      get(in, h.velocity[k]);
      get(in, h.acceleration[k]);
      get(in, h.angular_velocity[k]);
      get(in, h.angular_acceleration[k]);
    }
    get(in, search_.reference_positions());
    get(in, search_.rebuild_counter());
    get(in, search_.reference_time());
    get_list(in, pairs_);
    get_list(in, walls_);
    get(in, search_.reference_orientations());
    get_body_list(in, body_pairs_);
    get_body_list(in, body_walls_);
    for (PourSource& src : setup_.pour) get(in, src.inserted);
    std::vector<char> rng_state;
    get(in, rng_state);
    std::istringstream rng(std::string(rng_state.begin(), rng_state.end()));
    rng >> pour_rng_;
    get(in, max_overlap_ratio_);
    get(in, touching_pairs_);
    get(in, touching_walls_);
    ParticleStore& p = setup_.particles;
    if (without_keys) {
      // Storage order was the order of creation: keys that keep it the (key, id) order.
      p.sort_key.resize(p.size());
      std::iota(p.sort_key.begin(), p.sort_key.end(), std::uint64_t{0});
    } else {
      get(in, p.sort_key);
      if (p.sort_key.size() != p.size()) throw std::runtime_error("checkpoint is inconsistent");
    }
    if (!without_twist) {
      get(in, body_pairs_.twist);
      get(in, body_walls_.twist);
      if (body_pairs_.twist.size() != body_pairs_.size() ||
          body_walls_.twist.size() != body_walls_.size()) {
        throw std::runtime_error("checkpoint contact list is inconsistent");
      }
      if (twist_angles) {
        body_pairs_.twist.assign(body_pairs_.size(), 0.0);
        body_walls_.twist.assign(body_walls_.size(), 0.0);
      }
    }
    choose_threads();
    build_incidence();
  } catch (const std::runtime_error& e) {
    throw InputError(file.string(), "", e.what());
  }
}

}  // namespace sanguis::dem
