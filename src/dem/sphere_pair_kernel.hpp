#pragma once
// Sphere-sphere contacts evaluated a batch at a time (eq. 2.5-2.13 through
// evaluate_contact), so that the arithmetic runs on several contacts at once.
//
// Why batches: one contact is a long chain of dependent operations (a square root,
// a division, the Coulomb test, a second square root and division when sliding)
// that the processor cannot overlap much with the next contact's chain when the
// two are interleaved with the force accumulation. Here a batch is done in three
// passes: (1) gather the particle data and the memory of each contact into lanes
// (scalar loads, independent, so they overlap in the memory system); (2) run the
// contact law on all lanes in one loop over plain arrays, which the compiler turns
// into vector code (branches become selects: needs -fno-trapping-math, set in the
// top CMakeLists.txt; not `omp simd`, whose per-lane copies of the structs
// evaluate_contact works on keep GCC 12 from vectorizing); (3) write the memories
// back and hand each outcome to the caller, which adds it to the particles: in contact
// order, as before, so the forces are summed in the same order.
//
// Pass (2) calls the same evaluate_contact as every other contact, on the same
// operands in the same order, and vector lanes round exactly as scalar operations
// do (no fused multiply-add: -ffp-contract=off), so the results are bit for bit
// those of one contact at a time (test_sphere_pair_kernel.cpp checks it).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/vec3.hpp"
#include "dem/contact_law.hpp"
#include "dem/contact_parameters.hpp"
#include "dem/domain.hpp"

namespace sanguis::dem {

// One batch: inputs gathered per lane, then outputs per lane. Structure of arrays.
struct SpherePairLanes {
  static constexpr int kLanes = 16;
  // Inputs.
  alignas(64) double dx[kLanes], dy[kLanes], dz[kLanes];  // x_j - x_i (nearest image)
  alignas(64) double ri[kLanes], rj[kLanes];
  alignas(64) double dvx[kLanes], dvy[kLanes], dvz[kLanes];  // v_i - v_j
  alignas(64) double wix[kLanes], wiy[kLanes], wiz[kLanes];
  alignas(64) double wjx[kLanes], wjy[kLanes], wjz[kLanes];
  alignas(64) double kn[kLanes], eta_n[kLanes], kt[kLanes], eta_t[kLanes], mu[kLanes];
  alignas(64) double kr[kLanes], eta_r[kLanes], mu_r[kLanes];
  // Memory, read and written back (ContactHistory by components).
  alignas(64) double tx[kLanes], ty[kLanes], tz[kLanes];  // tangential displacement
  alignas(64) double mx[kLanes], my[kLanes], mz[kLanes];  // rolling spring torque
  alignas(64) double nx[kLanes], ny[kLanes], nz[kLanes];  // previous normal
  // Outputs.
  alignas(64) double fx[kLanes], fy[kLanes], fz[kLanes];     // force on the first sphere
  alignas(64) double t1x[kLanes], t1y[kLanes], t1z[kLanes];  // torque on the first
  alignas(64) double t2x[kLanes], t2y[kLanes], t2z[kLanes];  // torque on the second
  alignas(64) double ratio[kLanes];                          // overlap / smaller radius
  alignas(64) double touching[kLanes];  // 1 or 0 (a double: the vector loop has one lane width)
  std::size_t pair[kLanes];             // material pair (index into the contact table)
  bool uniform = true;                  // every lane has the material pair of lane 0
  bool rolling = false;                 // some lane has rolling resistance
};

// Lane l of three component arrays, as a vector.
[[gnu::always_inline]] inline void put_lane(double* x, double* y, double* z, int l, const Vec3& v) {
  x[l] = v.x;
  y[l] = v.y;
  z[l] = v.z;
}
[[gnu::always_inline]] inline Vec3 lane(const double* x, const double* y, const double* z, int l) {
  return {x[l], y[l], z[l]};
}

// Read-only view of what the sphere-sphere law needs; `history` is read and written.
struct SpherePairInputs {
  const Vec3* position;
  const Vec3* velocity;
  const Vec3* angular_velocity;
  const double* radius;
  const std::int32_t* material;
  const ContactParameters* table;  // materials x materials, row-major (ContactTable)
  std::size_t materials;
  const std::uint32_t* first;
  const std::uint32_t* second;
  ContactHistory* history;
  const Domain* domain;
  bool periodic;
  double dt;
};

// Kinematics of two spheres of radii ri, rj whose centres are d apart (d = x_j - x_i,
// dist2 = |d|^2, within ri + rj), with v_i - v_j = dv and spins wi, wj; a_i and a_j are
// the lever arms from the centres to the contact point.
struct SpherePairGeometry {
  ContactKinematics kinematics;
  double a_i = 0.0, a_j = 0.0;
};

[[gnu::always_inline]] inline SpherePairGeometry sphere_pair_geometry(const Vec3& d, double dist2,
                                                                      double ri, double rj,
                                                                      const Vec3& dv,
                                                                      const Vec3& wi,
                                                                      const Vec3& wj) {
  SpherePairGeometry g;
  ContactKinematics& c = g.kinematics;
  const double sum_r = ri + rj;
  const double dist = std::sqrt(dist2);
  c.normal = dist > 0.0 ? (1.0 / dist) * d : Vec3{0.0, 0.0, 1.0};
  c.overlap = sum_r - dist;
  // Lever arms from the centres to the contact point (midpoint of the overlap):
  // C - x_i = a_i n and C - x_j = -a_j n, so both moments share n x F.
  g.a_i = ri - 0.5 * c.overlap;
  g.a_j = rj - 0.5 * c.overlap;
  c.relative_velocity = dv + cross(g.a_i * wi + g.a_j * wj, c.normal);
  c.relative_angular_velocity = wi - wj;
  c.reduced_radius = ri * rj / sum_r;
  return g;
}

// Pass (1): contact index(l) into lane l, for l < n.
template <class Index>
[[gnu::always_inline]] inline void gather_sphere_pairs(const SpherePairInputs& in, Index index,
                                                       int n, SpherePairLanes& b) {
  b.uniform = true;
  b.rolling = false;
  const bool one_material = in.materials == 1;  // then every pair is pair 0: no lookup
  const auto pair_of = [&in, one_material](std::uint32_t i, std::uint32_t j) {
    return one_material ? std::size_t{0}
                        : static_cast<std::size_t>(in.material[i]) * in.materials +
                              static_cast<std::size_t>(in.material[j]);
  };
  const std::size_t first_pair = n > 0 ? pair_of(in.first[index(0)], in.second[index(0)]) : 0;
  for (int l = 0; l < n; ++l) {
    const std::size_t k = index(l);
    const std::uint32_t i = in.first[k], j = in.second[k];
    Vec3 d = in.position[j] - in.position[i];
    if (in.periodic) d = in.domain->near_image(d);
    put_lane(b.dx, b.dy, b.dz, l, d);
    b.ri[l] = in.radius[i];
    b.rj[l] = in.radius[j];
    const Vec3 dv = in.velocity[i] - in.velocity[j];
    put_lane(b.dvx, b.dvy, b.dvz, l, dv);
    const Vec3& wi = in.angular_velocity[i];
    const Vec3& wj = in.angular_velocity[j];
    put_lane(b.wix, b.wiy, b.wiz, l, wi);
    put_lane(b.wjx, b.wjy, b.wjz, l, wj);
    const std::size_t pair = pair_of(i, j);
    b.pair[l] = pair;
    b.uniform = b.uniform && pair == first_pair;
    b.mu_r[l] = in.table[pair].rolling_friction;  // read per lane (evaluate_sphere_lanes)
    const ContactHistory& h = in.history[k];
    put_lane(b.tx, b.ty, b.tz, l, h.tangential_displacement);
    put_lane(b.mx, b.my, b.mz, l, h.rolling_spring_torque);
    put_lane(b.nx, b.ny, b.nz, l, h.normal);
  }
  // The parameters: lane 0 only when they are uniform (evaluate_sphere_lanes reads no other).
  for (int l = 0; l < (b.uniform ? std::min(n, 1) : n); ++l) {
    const ContactParameters& p = in.table[b.pair[l]];
    b.rolling = b.rolling || p.rolling_friction > 0.0;
    b.kn[l] = p.normal_stiffness;
    b.eta_n[l] = p.normal_damping;
    b.kt[l] = p.tangential_stiffness;
    b.eta_t[l] = p.tangential_damping;
    b.mu[l] = p.friction;
    b.kr[l] = p.rolling_stiffness;
    b.eta_r[l] = p.rolling_damping;
  }
}

// Pass (2): the contact law on every lane (eq. 2.5-2.13). Lanes that do not touch are
// computed too and discarded by pass (3): no branch depends on the lane.
//
// kRolling false: every lane has rolling_friction <= 0, so evaluate_contact's rolling
// branch is not taken on any lane and is compiled out (the lanes' rolling parameters are
// replaced by zeros, which take the same branch). kUniform: every lane has the parameters
// of lane 0, read once (the common case of one material).
template <bool kRolling, bool kUniform>
void evaluate_sphere_lanes(SpherePairLanes& b, int n, double dt) {
  const auto param = [](const double* lanes, int l) __attribute__((always_inline)) {
    return kUniform ? lanes[0] : lanes[l];
  };
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
  for (int l = 0; l < n; ++l) {
    const Vec3 d = lane(b.dx, b.dy, b.dz, l);
    const double ri = b.ri[l], rj = b.rj[l];
    const double sum_r = ri + rj;
    const double dist2 = norm2(d);
    b.touching[l] = dist2 > sum_r * sum_r ? 0.0 : 1.0;
    const SpherePairGeometry g =
        sphere_pair_geometry(d, dist2, ri, rj, lane(b.dvx, b.dvy, b.dvz, l),
                             lane(b.wix, b.wiy, b.wiz, l), lane(b.wjx, b.wjy, b.wjz, l));
    const ContactKinematics& c = g.kinematics;
    const Vec3& normal = c.normal;
    const double a_i = g.a_i, a_j = g.a_j;
    ContactParameters p;
    p.normal_stiffness = param(b.kn, l);
    p.normal_damping = param(b.eta_n, l);
    p.tangential_stiffness = param(b.kt, l);
    p.tangential_damping = param(b.eta_t, l);
    p.friction = param(b.mu, l);
    if constexpr (kRolling) {
      p.rolling_stiffness = param(b.kr, l);
      p.rolling_damping = param(b.eta_r, l);
      // Per lane even when uniform: GCC 12 does not vectorize the loop when the rolling
      // branch of evaluate_contact hangs on a value that is the same for every lane.
      p.rolling_friction = b.mu_r[l];
    }
    ContactHistory h;
    h.tangential_displacement = lane(b.tx, b.ty, b.tz, l);
    h.rolling_spring_torque = lane(b.mx, b.my, b.mz, l);
    h.normal = lane(b.nx, b.ny, b.nz, l);
    const ContactHistory before = h;
    const ContactResponse r = evaluate_contact(p, c, h, dt);
    const Vec3 moment = cross(normal, r.force);
    const Vec3 t1 = a_i * moment + r.rolling_torque;
    const Vec3 t2 = a_j * moment - r.rolling_torque;
    // A lane apart gives +0 forces and torques (a select, not a product: 0 x a negative
    // value would be -0), so its outcome adds nothing; its memory is forgotten (zeroed) if it
    // had one, else left as it was (a memory turned round by a renumbering holds -0s).
    const bool on = b.touching[l] != 0.0;
    const bool had = before.normal.x != 0.0 || before.normal.y != 0.0 || before.normal.z != 0.0;
    const auto keep = [on](const Vec3& v) __attribute__((always_inline)) {
      return on ? v : Vec3{};
    };
    const auto memory =
        [ on, had ](const Vec3& now, const Vec3& was) __attribute__((always_inline)) {
      return on ? now : (had ? Vec3{} : was);
    };
    put_lane(b.fx, b.fy, b.fz, l, keep(r.force));
    put_lane(b.t1x, b.t1y, b.t1z, l, keep(t1));
    put_lane(b.t2x, b.t2y, b.t2z, l, keep(t2));
    b.ratio[l] = on ? c.overlap / std::min(ri, rj) : 0.0;
    put_lane(b.tx, b.ty, b.tz, l,
             memory(h.tangential_displacement, before.tangential_displacement));
    put_lane(b.mx, b.my, b.mz, l, memory(h.rolling_spring_torque, before.rolling_spring_torque));
    put_lane(b.nx, b.ny, b.nz, l, memory(h.normal, before.normal));
  }
}

// Pass (3), for lane l: the memory back. A contact that does not touch forgets the memory it
// had (zeroed); one that had none is left as it was.
[[gnu::always_inline]] inline void store_sphere_history(const SpherePairLanes& b, int l,
                                                        ContactHistory& h) {
  // The lanes hold what the memory must become, touching or apart (evaluate_sphere_lanes):
  // no branch here.
  h.tangential_displacement = lane(b.tx, b.ty, b.tz, l);
  h.rolling_spring_torque = lane(b.mx, b.my, b.mz, l);
  h.normal = lane(b.nx, b.ny, b.nz, l);
}

// One contact at a time: the same operations as the three passes, with the branches
// taken rather than computed on both sides. Updates the memory of contact k.
[[gnu::always_inline]] inline ContactOutcome evaluate_sphere_pair(const SpherePairInputs& in,
                                                                  std::size_t k) {
  ContactOutcome out;
  const std::uint32_t i = in.first[k], j = in.second[k];
  ContactHistory& h = in.history[k];
  Vec3 d = in.position[j] - in.position[i];
  if (in.periodic) d = in.domain->near_image(d);
  const double ri = in.radius[i], rj = in.radius[j];
  const double sum_r = ri + rj;
  const double dist2 = norm2(d);
  if (dist2 > sum_r * sum_r) {
    if (h.normal.x != 0.0 || h.normal.y != 0.0 || h.normal.z != 0.0) h = ContactHistory{};
    return out;
  }
  const SpherePairGeometry g =
      sphere_pair_geometry(d, dist2, ri, rj, in.velocity[i] - in.velocity[j],
                           in.angular_velocity[i], in.angular_velocity[j]);
  const ContactKinematics& c = g.kinematics;
  const Vec3& normal = c.normal;
  const double a_i = g.a_i, a_j = g.a_j;
  const ContactParameters& p = in.table[static_cast<std::size_t>(in.material[i]) * in.materials +
                                        static_cast<std::size_t>(in.material[j])];
  const ContactResponse r = evaluate_contact(p, c, h, in.dt);
  const Vec3 moment = cross(normal, r.force);
  out.force = r.force;
  out.torque_first = a_i * moment + r.rolling_torque;
  out.torque_second = a_j * moment - r.rolling_torque;
  out.overlap_ratio = c.overlap / std::min(ri, rj);
  out.touching = true;
  return out;
}

// Lane l of a batch as a contact outcome.
[[gnu::always_inline]] inline ContactOutcome lane_outcome(const SpherePairLanes& b, int l) {
  // No branch: a lane apart holds zeros (evaluate_sphere_lanes), the empty outcome's values.
  ContactOutcome out;
  out.force = lane(b.fx, b.fy, b.fz, l);
  out.torque_first = lane(b.t1x, b.t1y, b.t1z, l);
  out.torque_second = lane(b.t2x, b.t2y, b.t2z, l);
  out.overlap_ratio = b.ratio[l];
  out.touching = b.touching[l] != 0.0;
  return out;
}

// The three passes on contacts index(0) .. index(n - 1), n <= kLanes; the third hands
// each outcome to use(k, outcome) once the memory of contact k is stored, in order.
template <class Index, class Use>
[[gnu::always_inline]] inline void evaluate_sphere_pairs_batched(const SpherePairInputs& in,
                                                                 Index index, int n,
                                                                 SpherePairLanes& b, Use use) {
  gather_sphere_pairs(in, index, n, b);
  if (b.rolling) {
    if (b.uniform) {
      evaluate_sphere_lanes<true, true>(b, n, in.dt);
    } else {
      evaluate_sphere_lanes<true, false>(b, n, in.dt);
    }
  } else if (b.uniform) {
    evaluate_sphere_lanes<false, true>(b, n, in.dt);
  } else {
    evaluate_sphere_lanes<false, false>(b, n, in.dt);
  }
  for (int l = 0; l < n; ++l) {
    const std::size_t k = index(l);
    store_sphere_history(b, l, in.history[k]);
    use(k, lane_outcome(b, l));
  }
}

// Contacts index(0) .. index(count - 1), one at a time, each handed to use(k, outcome).
template <class Index, class Use>
[[gnu::always_inline]] inline void evaluate_sphere_pairs_one_by_one(const SpherePairInputs& in,
                                                                    Index index, std::size_t count,
                                                                    Use use) {
  for (std::size_t e = 0; e < count; ++e) {
    const std::size_t k = index(e);
    use(k, evaluate_sphere_pair(in, k));
  }
}

// Batches pay where a vector register holds four doubles or more (dem-spheres benchmark,
// AMD EPYC, particle-steps/s: one contact at a time 8.9e6 in the baseline x86-64 build,
// batches 8.1e6 there with SSE2's two doubles per register, but 1.2e7 with AVX2 and 1.4e7
// with AVX-512; docs/performance.md). The build chooses; the results are the same bits.
#if defined(__AVX2__) || defined(__AVX512F__)
inline constexpr bool kBatchedSpherePairs = true;
#else
inline constexpr bool kBatchedSpherePairs = false;
#endif

// Contacts index(0) .. index(count - 1), their memories updated; use(k, outcome) is called
// for each, in that order, once contact k is complete. `b` is working space.
template <class Index, class Use>
[[gnu::always_inline]] inline void evaluate_sphere_pairs(const SpherePairInputs& in, Index index,
                                                         std::size_t count, SpherePairLanes& b,
                                                         Use use) {
  if constexpr (kBatchedSpherePairs) {
    constexpr auto lanes = static_cast<std::size_t>(SpherePairLanes::kLanes);
    for (std::size_t e0 = 0; e0 < count; e0 += lanes) {
      const int n = static_cast<int>(std::min(lanes, count - e0));
      const auto batch_index = [&index, e0](int l) {
        return index(e0 + static_cast<std::size_t>(l));
      };
      evaluate_sphere_pairs_batched(in, batch_index, n, b, use);
    }
  } else {
    evaluate_sphere_pairs_one_by_one(in, index, count, use);
  }
}

}  // namespace sanguis::dem
