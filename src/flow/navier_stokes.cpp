#include "flow/navier_stokes.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace sanguis::flow {

namespace {

constexpr std::size_t D(int d) {
  return static_cast<std::size_t>(d);
}
using Strides = std::array<std::ptrdiff_t, 3>;

/// The time step and the cell size of one block, for the BCG kernels.
/// `finest_h` < h asks for the level-matched face value (below); h or more
/// (the default) does not.
struct StepScales {
  double dt = 0.0;
  double h = 0.0;
  double finest_h = std::numeric_limits<double>::infinity();
};

/// A block's StepScales; `level_matched`: NavierStokesOptions::level_matched_advection.
StepScales step_scales(const Forest& forest, bool level_matched, int blk, double dt) {
  const Block& block = forest.block(blk);
  const double h = block.length / forest.block_cells();
  if (!level_matched || block.level >= forest.max_level()) return StepScales{dt, h, h};
  return StepScales{dt, h, std::ldexp(h, block.level - forest.max_level())};
}

/// The term that gives a BCG face value of a block coarser than the finest
/// the finest level's leading error (NavierStokesOptions::level_matched_advection).
/// BCG takes the value at t + dt/2 where the characteristic through the face
/// starts at t, a/2 upwind of the face (a = |un| dt, the same on every level:
/// one dt for all); the line through the upwind cell with its central slope
/// misses it by -(h - a)^2/8 f''. Adding ((h - a)^2 - (h_f - a)^2)/8 f''
/// leaves -(h_f - a)^2/8 f'' on every level, so the error no longer jumps at a
/// coarse-fine face, where the jump leaves an O(h) truncation error in the
/// interface cells (docs/theory/flow.md, "Still open", the paragraph "Then the
/// same idea without touching uniform grids"). Where a >= h_f (a coarse block
/// whose flow is faster than the finest blocks'; no finest cell has such an
/// error) the target is zero, the full quadratic: unclamped, the term would
/// anti-diffuse, unstable in 1D from a coarse Courant number of about 0.8.
/// `reach` = 1 - a/h; `second_difference` the upwind cell's, h^2 f''.
inline double level_matched_term(const StepScales& k, double un, double reach,
                                 double second_difference) {
  const double finest_reach = std::max(0.0, (k.finest_h - std::abs(un) * k.dt) / k.h);
  return 0.125 * (reach * reach - finest_reach * finest_reach) * second_difference;
}

/// Calls body(std::true_type{}) where `level_matched` holds, else
/// body(std::false_type{}): the BCG row kernel is chosen once per block.
template <typename Body>
inline void with_level_matching(bool level_matched, Body&& body) {
  if (level_matched) {
    body(std::true_type{});
  } else {
    body(std::false_type{});
  }
}

/// Bell-Colella-Glaz upwind value at the lower d-face of cell c (between
/// c - s_d and c) at t + dt/2 (Bell, Colella & Glaz 1989, as in Basilisk's
/// bcg.h): the upwind cell value extrapolated by its central slope, a source
/// term (`source` = dt/4 (src_c + src_{c-s_d}), src the cell source), and transverse upwind
/// corrections with the transverse velocities `vt` of the upwind cell.
inline double bcg_face_value(const double* f, double source, double un, const StepScales& k, int d,
                             std::ptrdiff_t c, const Strides& s, const std::array<double, 3>& vt) {
  const double sign = un > 0.0 ? 1.0 : -1.0;
  const double courant = k.dt * un / k.h;
  const std::ptrdiff_t up = un > 0.0 ? c - s[D(d)] : c;
  const double slope = 0.5 * (f[up + s[D(d)]] - f[up - s[D(d)]]);  // h df/dx
  double value = f[up] + source + 0.5 * sign * (1.0 - sign * courant) * slope;
  if (k.finest_h < k.h) {
    value += level_matched_term(k, un, 1.0 - sign * courant,
                                f[up + s[D(d)]] - 2.0 * f[up] + f[up - s[D(d)]]);
  }
  for (int e = 0; e < 3; ++e) {
    if (e == d) continue;
    const double vn = vt[D(e)];
    const double df = vn < 0.0 ? f[up + s[D(e)]] - f[up] : f[up] - f[up - s[D(e)]];
    value -= k.dt * vn * df / (2.0 * k.h);
  }
  return value;
}

/// bcg_face_value() on the lower Dir-faces c = row + i, i in [0, n), of one
/// row along x, written without branches so that the loop vectorises: both
/// candidate upwind cells (c - s_Dir and c) are read and the value of the
/// upwind one selected, so every face takes the same operations, in the same
/// order, as bcg_face_value (the same bits). `normal(c)` gives the face's
/// normal velocity, `transverse(e, q)` the transverse velocity along e
/// carried by cell q, `source(c)` the source term; `store(c, value, un)`.
/// `LevelMatched`: the block is coarser than the finest and takes
/// level_matched_term (chosen per block, so the finest blocks' loop is as before).
template <int Dir, bool LevelMatched = false, typename Normal, typename Transverse, typename Source,
          typename Store>
inline void bcg_face_row(const double* f, std::ptrdiff_t row, int n, const Strides& s,
                         const StepScales& k, Normal&& normal, Transverse&& transverse,
                         Source&& source, Store&& store) {
  // The transverse directions in increasing order, as bcg_face_value's loop.
  constexpr int Ea = Dir == 0 ? 1 : 0, Eb = Dir == 2 ? 1 : 2;
  const std::ptrdiff_t sd = s[D(Dir)], sa = s[D(Ea)], sb = s[D(Eb)];
  // `store` writes an array that no callback reads (face values or fluxes):
  // without this, the aliasing tests needed exceed what GCC will version.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
  for (std::ptrdiff_t c = row; c < row + n; ++c) {
    const double un = normal(c);
    const bool positive = un > 0.0;
    const std::ptrdiff_t lo = c - sd;  // the upwind cell when un > 0; else c
    const double sign = positive ? 1.0 : -1.0;
    const double courant = k.dt * un / k.h;
    // Every candidate is loaded, whichever is used: a load under a condition
    // would be a masked load, which keeps the loop scalar.
    const double f_lo2 = f[lo - sd], f_lo = f[lo], f_c = f[c], f_hi = f[c + sd];
    const double f_up = positive ? f_lo : f_c;
    const double f_next = positive ? f_c : f_hi;
    const double f_prev = positive ? f_lo2 : f_lo;
    const double slope = 0.5 * (f_next - f_prev);
    double value = f_up + source(c) + 0.5 * sign * (1.0 - sign * courant) * slope;
    if constexpr (LevelMatched) {
      value += level_matched_term(k, un, 1.0 - sign * courant, f_next - 2.0 * f_up + f_prev);
    }
    const auto correct = [&](int e, std::ptrdiff_t se) {
      const double v_lo = transverse(e, lo), v_c = transverse(e, c);
      const double above_lo = f[lo + se], above_c = f[c + se];
      const double below_lo = f[lo - se], below_c = f[c - se];
      const double vn = positive ? v_lo : v_c;
      const double above = positive ? above_lo : above_c;
      const double below = positive ? below_lo : below_c;
      const double df = vn < 0.0 ? above - f_up : f_up - below;
      value -= k.dt * vn * df / (2.0 * k.h);
    };
    correct(Ea, sa);
    correct(Eb, sb);
    store(c, value, un);
  }
}

/// h^2 times the transverse Laplacian, at the d-face below cell c, of the
/// cell-centred point values g(q): the mean of the two cells' second
/// differences across the face's two tangential directions. The mean of a
/// smooth field over a face of side h is its centre value plus 1/24 of this.
template <typename Values>
inline double transverse_second_differences(Values&& g, int d, std::ptrdiff_t c, const Strides& s) {
  const std::ptrdiff_t lo = c - s[D(d)];
  double sum = 0.0;
  for (int t = 0; t < 3; ++t) {
    if (t == d) continue;
    const std::ptrdiff_t st = s[D(t)];
    sum += (g(c + st) - 2.0 * g(c) + g(c - st)) + (g(lo + st) - 2.0 * g(lo) + g(lo - st));
  }
  return 0.5 * sum;
}

/// Mean over the d-face below cell c of the cell-centred field f, to O(h^4):
/// the cubic through the four cells along d, plus the transverse correction.
/// A coarse face beside finer blocks takes the mean of the fine faces (the
/// fine faces win), which is a face mean; the plain average of two cells is
/// a point value, O(h^2) off the face mean, and the difference divided by h
/// left an O(h) divergence in the coarse cells along every coarse-fine face
/// (issue #7). Needs two ghost layers along d, one across.
/// `cubic` false: the plain average along d; `transverse` false: no correction.
inline double face_mean(const double* f, int d, std::ptrdiff_t c, const Strides& s, bool cubic,
                        bool transverse) {
  const std::ptrdiff_t n = s[D(d)];
  const double along = cubic ? (9.0 * (f[c] + f[c - n]) - (f[c + n] + f[c - 2 * n])) / 16.0
                             : 0.5 * (f[c] + f[c - n]);
  if (!transverse) return along;
  return along +
         transverse_second_differences([f](std::ptrdiff_t q) { return f[q]; }, d, c, s) / 24.0;
}

/// out = face_mean + dt a over `count` faces along x from c0, with the
/// stencil's choices fixed for the whole span: the direction and both flags
/// compile-time constants, so the loop vectorises (the same operations per
/// face as the scalar call: the same bits).
template <int kD, bool kCubic, bool kTransverse>
void face_means_in_row(double* out, const double* f, const double* a, std::ptrdiff_t c0, int count,
                       const Strides& s, double dt) {
  for (std::ptrdiff_t c = c0; c < c0 + count; ++c)
    out[c] = face_mean(f, kD, c, s, kCubic, kTransverse) + dt * a[c];
}

template <int kD>
void face_means_in_row(double* out, const double* f, const double* a, std::ptrdiff_t c0, int count,
                       const Strides& s, double dt, bool cubic, bool transverse) {
  if (count <= 0) return;
  if (cubic && transverse) return face_means_in_row<kD, true, true>(out, f, a, c0, count, s, dt);
  if (cubic) return face_means_in_row<kD, true, false>(out, f, a, c0, count, s, dt);
  if (transverse) return face_means_in_row<kD, false, true>(out, f, a, c0, count, s, dt);
  face_means_in_row<kD, false, false>(out, f, a, c0, count, s, dt);
}

/// Whether every cell of face_mean's stencil at the d-face below c is fluid
/// (solid cells hold u = 0, not a smooth extension of the flow).
inline bool face_mean_stencil_is_fluid(const double* solid, int d, std::ptrdiff_t c,
                                       const Strides& s) {
  const std::ptrdiff_t n = s[D(d)];
  for (std::ptrdiff_t q : {c - 2 * n, c - n, c, c + n})
    if (solid[q] != 0.0) return false;
  for (int t = 0; t < 3; ++t) {
    if (t == d) continue;
    for (std::ptrdiff_t q : {c + s[D(t)], c - s[D(t)], c - n + s[D(t)], c - n - s[D(t)]})
      if (solid[q] != 0.0) return false;
  }
  return true;
}

/// Whether cell number n (0..b-1) along t lies beside one of the block's
/// faces across t that `prescribed` marks.
inline bool beside_prescribed(const std::array<bool, 6>& prescribed, int t, int n, int b) {
  return (n == 0 && prescribed[D(face_index(t, 0))]) ||
         (n == b - 1 && prescribed[D(face_index(t, 1))]);
}

/// Viscosity on the face between two cells: the harmonic mean, so that a
/// viscosity jump on a face passes the shear stress exactly (layered Couette).
inline double face_viscosity(double left, double right) {
  const double sum = left + right;
  return sum > 0.0 ? 2.0 * left * right / sum : 0.0;
}

/// Whether the lower (side 0) or upper (side 1) d-face of a block is on the domain boundary.
bool on_boundary(const Block& block, int d, int side) {
  std::array<int, 3> o{0, 0, 0};
  o[D(d)] = side == 0 ? -1 : 1;
  return block.neighbours[D(neighbour_slot(o[0], o[1], o[2]))].link == Link::Boundary;
}

/// Calls body(c, f) for every cell c of the block's layer beside face (d, side)
/// and the index f of that face in a face field (c on the lower face, c + s_d
/// on the upper one).
template <typename Body>
void for_face_layer(const BlockLayout& L, int d, int side, Body&& body) {
  for_face_cells(L, d, side,
                 [&](std::ptrdiff_t c, std::ptrdiff_t g) { body(c, side == 0 ? c : g); });
}

/// Whether the block's neighbour across face (d, side) is a block with level relation `jump`.
bool face_neighbour_is(const Block& block, int d, int side, LevelJump jump) {
  const Neighbour& nb = block.neighbours[face_neighbour_slot(d, side)];
  return nb.link != Link::Boundary && nb.jump == jump;
}

/// Face values sent across block faces through the ordinary exchange (the
/// trick of Multigrid::match_fluxes): every block writes value(blk, d, f) of
/// its faces f on each block face whose neighbour has relation `toward`
/// into its face layer of layers[face], and the exchange carries them into
/// the neighbour's ghost cell across. Same level: the ghost is the copy
/// itself. Toward a coarser block (the fine faces win): the coarse ghost is
/// the mean of the 8 fine cells behind it, the 4 of the face layer and 4
/// zeros (the layers are only ever written in their face layer), so twice
/// the ghost is the mean of the 4 fine faces.
template <typename Value>
void send_faces(const Forest& forest, std::array<BlockField, 6>& layers, LevelJump toward,
                Value&& value) {
  const BlockLayout L = layers[0].layout();
  forest.for_each_block([&](int blk) {
    const Block& block = forest.block(blk);
    for (int d = 0; d < 3; ++d)
      for (int side = 0; side < 2; ++side) {
        if (!face_neighbour_is(block, d, side, toward)) continue;
        double* layer = layers[D(face_index(d, side))].block(blk);
        for_face_layer(L, d, side,
                       [&](std::ptrdiff_t c, std::ptrdiff_t f) { layer[c] = value(blk, d, f); });
      }
  });
  if (toward == LevelJump::Coarser) {
    // Only the coarse blocks' ghosts across faces towards finer blocks are
    // read (for_received_faces from Finer), and the neighbour wrote under
    // its own face, the opposite one: each layer travels to that face alone,
    // without the same-level copies and the fine-side interpolations of a
    // full exchange of six fields (same bits; docs/performance.md).
    for (int f = 0; f < 6; ++f) forest.exchange_from_finer(layers[D(f)], f ^ 1);
    return;
  }
  std::array<BlockField*, 6> fields{};
  for (std::size_t f = 0; f < 6; ++f) fields[f] = &layers[f];
  forest.exchange(fields, 1, true);
}

/// The receiving half, for one block: use(d, side, f, v) for every face f of
/// it on a block face (d, side) whose neighbour has relation `from` (Same:
/// the neighbour's copy; Finer: the mean of the 4 fine faces across).
template <typename Use>
void for_received_faces(const Forest& forest, const std::array<BlockField, 6>& layers, int blk,
                        LevelJump from, Use&& use) {
  const BlockLayout L = layers[0].layout();
  const Block& block = forest.block(blk);
  const double factor = from == LevelJump::Finer ? 2.0 : 1.0;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      if (!face_neighbour_is(block, d, side, from)) continue;
      // The neighbour wrote under its own face: the opposite one.
      const double* sent = layers[D(face_index(d, 1 - side))].block(blk);
      const std::ptrdiff_t beyond = side == 0 ? -L.stride(d) : L.stride(d);
      for_face_layer(L, d, side, [&](std::ptrdiff_t c, std::ptrdiff_t f) {
        use(d, side, f, factor * sent[c + beyond]);
      });
    }
}

std::array<BcKind, 6> velocity_kinds(const std::array<FlowBoundary, 6>& bcs) {
  std::array<BcKind, 6> kinds{};
  for (std::size_t f = 0; f < 6; ++f) {
    switch (bcs[f].kind) {
      case FlowBoundaryKind::Periodic:
        kinds[f] = BcKind::Periodic;
        break;
      case FlowBoundaryKind::Wall:
      case FlowBoundaryKind::Inflow:
        kinds[f] = BcKind::Dirichlet;
        break;
      case FlowBoundaryKind::Outflow:
        kinds[f] = BcKind::Neumann;
        break;
    }
  }
  return kinds;
}

// The pressure's condition is the dual of the velocity's: where the velocity is
// given (walls, inflow) the pressure has a zero normal gradient, and at an
// outflow, where the velocity has one, the pressure is given.
std::array<BcKind, 6> pressure_kinds(const std::array<FlowBoundary, 6>& bcs) {
  std::array<BcKind, 6> kinds = velocity_kinds(bcs);
  for (BcKind& k : kinds) {
    if (k == BcKind::Dirichlet) {
      k = BcKind::Neumann;
    } else if (k == BcKind::Neumann) {
      k = BcKind::Dirichlet;
    }
  }
  return kinds;
}

const std::array<FlowBoundary, 6>& checked(const Forest& forest,
                                           const std::array<FlowBoundary, 6>& bcs) {
  for (int d = 0; d < 3; ++d) {
    for (int side = 0; side < 2; ++side) {
      const FlowBoundary& bc = bcs[D(face_index(d, side))];
      const bool periodic = forest.spec().periodic[D(d)];
      if ((bc.kind == FlowBoundaryKind::Periodic) != periodic) {
        throw std::invalid_argument("navier-stokes: boundary " +
                                    std::to_string(face_index(d, side)) +
                                    " must be periodic exactly when the forest is periodic there");
      }
      if (bc.kind == FlowBoundaryKind::Wall && bc.wall_velocity[d] != 0.0) {
        throw std::invalid_argument("navier-stokes: a wall can only move tangentially");
      }
      if (bc.kind == FlowBoundaryKind::Inflow && !bc.inflow) {
        throw std::invalid_argument("navier-stokes: an inflow boundary needs a velocity profile");
      }
    }
  }
  return bcs;
}

}  // namespace

NavierStokes::NavierStokes(const Forest& forest, const std::array<FlowBoundary, 6>& boundaries,
                           const Fluid& fluid, const NavierStokesOptions& options)
    : forest_(forest),
      boundaries_(checked(forest, boundaries)),
      fluid_(fluid),
      options_(options),
      pressure_mg_(std::in_place, forest, pressure_kinds(boundaries), options.merge_solver_blocks),
      viscous_mg_(std::in_place, forest, velocity_kinds(boundaries), options.merge_solver_blocks) {
  if (!(fluid.density > 0.0) || !(fluid.viscosity >= 0.0)) {
    throw std::invalid_argument("navier-stokes: density must be > 0 and viscosity >= 0");
  }
  const int n = forest.local_blocks();
  const int b = forest.block_cells();
  u_ = make_vector_field(n, b);
  g_ = make_vector_field(n, b);
  uf_ = make_vector_field(n, b);
  accel_ = make_vector_field(n, b);
  p_ = BlockField(n, b);
  predictor_p_ = BlockField(n, b);
  viscous_increment_ = make_vector_field(n, b);
  mu_ = BlockField(n, b);
  mu_.fill(fluid.viscosity);
  allocate_work_fields();
  const auto vk = velocity_kinds(boundaries_);
  for (int c = 0; c < 3; ++c) {
    ScalarBoundary& bc = velocity_bc_[D(c)];
    bc.kind = vk;
    for (std::size_t f = 0; f < 6; ++f) {
      const FlowBoundary& fb = boundaries_[f];
      if (fb.kind == FlowBoundaryKind::Wall) {
        const double value = fb.wall_velocity[c];
        if (value != 0.0) bc.value[f] = [value](const Vec3&) { return value; };
      } else if (fb.kind == FlowBoundaryKind::Inflow) {
        bc.value[f] = [this, f, c](const Vec3& x) { return boundaries_[f].inflow(x, bc_time_)[c]; };
      }
    }
  }
  pressure_bc_.kind = pressure_kinds(boundaries_);
}

// Reshaped rather than allocated afresh: a regrid reuses the storage (freshly
// allocated fields cost page faults on top of the zeroing, about half of a
// regrid on the wake benchmark).
void NavierStokes::allocate_work_fields() {
  const int n = forest_.local_blocks();
  const int b = forest_.block_cells();
  reshape(scratch_, n, b);
  solid_.reshape(n, b);
  reshape(open_, n, b);
  for (auto& f : open_) f.fill(1.0);
  composite_ = !forest_.uniform();
  for (auto& layer : interface_) {
    if (composite_) {
      layer.reshape(n, b);
    } else {
      layer = BlockField();
    }
  }
  if (composite_) {
    reshape(face_flux_, n, b);
  } else {
    face_flux_ = FaceField{};
  }
}

void NavierStokes::set_velocity(const std::function<Vec3(const Vec3&)>& u0, double time) {
  const int b = forest_.block_cells();
  time_ = time;
  bc_time_ = time;
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    for_each_cell(b, [&](int i, int j, int k) {
      const Vec3 x{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                   block.lower.z + (k + 0.5) * h};
      const Vec3 v = u0(x);
      for (int c = 0; c < 3; ++c) u_[D(c)](blk, i, j, k) = v[c];
    });
  });
  // Project the initial field: uf exactly divergence-free, u corrected.
  face_average_plus_acceleration(0.0);
  BlockField& phi = scratch_[1];
  phi.fill(0.0);
  pressure_report_ = project(phi);
  forest_.for_each_block([&](int blk) {
    const double h = forest_.block(blk).length / b;
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t s = phi.layout().stride(d);
      double* ub = u_[D(d)].block(blk);
      const double* pb = phi.block(blk);
      for_each_cell(b, [&](int i, int j, int k) {
        const std::ptrdiff_t c = phi.layout().index(i, j, k);
        ub[c] -= 0.5 * ((pb[c + s] - pb[c]) + (pb[c] - pb[c - s])) / h;
      });
    }
  });
  p_.fill(0.0);
  predictor_p_.fill(0.0);
  for (auto& f : viscous_increment_) f.fill(0.0);
  // g = a until the first projection gives a pressure.
  forest_.for_each_block([&](int blk) {
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t s = p_.layout().stride(d);
      const double* ab = accel_[D(d)].block(blk);
      double* gb = g_[D(d)].block(blk);
      for_each_cell(b, [&](int i, int j, int k) {
        const std::ptrdiff_t c = p_.layout().index(i, j, k);
        gb[c] = 0.5 * (ab[c] + ab[c + s]);
      });
    }
  });
  clear_solid_cells(u_);
  fill_velocity_ghosts(u_);
}

void NavierStokes::set_body_force(const std::function<Vec3(const Vec3&)>& f) {
  if (&f != &body_force_) body_force_ = f;
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    for (int d = 0; d < 3; ++d) {
      for_each_face(b, d, [&](int i, int j, int k) {
        Vec3 x{block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
               block.lower.z + (k + 0.5) * h};
        x[d] -= 0.5 * h;
        accel_[D(d)](blk, i, j, k) = f(x)[d] / fluid_.density;
      });
    }
  });
}

void NavierStokes::set_viscosity(const std::function<double(const Vec3&)>& mu) {
  if (&mu != &viscosity_function_) viscosity_function_ = mu;
  if (!mu) return;  // forget the function, keep the values
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    for_each_cell(b, [&](int i, int j, int k) {
      mu_(blk, i, j, k) = mu({block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                              block.lower.z + (k + 0.5) * h});
    });
  });
  viscosity_changed_ = true;
}

void NavierStokes::set_solid(const std::function<bool(const Vec3&)>& solid) {
  // Closed faces (beta = 0) at a coarse-fine face have no matched flux in the
  // multigrid, and the no-slip closure there is not written for two levels:
  // blocks near solids must be at the finest level.
  std::function<bool(const Vec3&)> previous = std::move(solid_function_);
  solid_function_ = solid;
  if (composite_ && blocks_near_solids_below(forest_.max_level()) > 0) {
    solid_function_ = std::move(previous);  // the solver stays as it was
    throw std::invalid_argument(
        "navier-stokes: solid cells within 2 cells of a block coarser than the finest level; "
        "refine the blocks near solids to the finest level first (regrid with max_level does)");
  }
  sample_solid();
  clear_solid_cells(u_);
  close_solid_faces(uf_);
}

void NavierStokes::sample_solid() {
  const int b = forest_.block_cells();
  bool any = false;
  solid_.fill(0.0);
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    for_each_cell(b, [&](int i, int j, int k) {
      const bool inside =
          solid_function_({block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                           block.lower.z + (k + 0.5) * h});
      solid_(blk, i, j, k) = inside ? 1.0 : 0.0;
      any = any || inside;
    });
  }
  has_solids_ = forest_.max(any ? 1.0 : 0.0) > 0.0;
  fill_scalar_neumann(solid_, 2);  // face_mean's stencil reaches two cells out
  forest_.for_each_block([&](int blk) {
    const BlockLayout L = solid_.layout();
    const double* sb = solid_.block(blk);
    for (int d = 0; d < 3; ++d) {
      double* ob = open_[D(d)].block(blk);
      for_each_face(b, d, [&](int i, int j, int k) {
        const std::ptrdiff_t c = L.index(i, j, k);
        ob[c] = (sb[c] == 0.0 && sb[c - L.stride(d)] == 0.0) ? 1.0 : 0.0;
      });
    }
  });
  // Solid cells leave the pressure problem: all their faces are closed
  // (beta = 0), so the multigrid treats them as inactive.
  pressure_mg_->set_coefficients(nullptr, has_solids_ ? &open_ : nullptr);
  viscosity_changed_ = true;
}

bool NavierStokes::near_solid(const Vec3& lower, double length, int level) const {
  const ForestSpec& spec = forest_.spec();
  const int b = forest_.block_cells();
  // Blocks coarser than the initial grid test each of their cells at its
  // resolution, so that a solid one initial cell thick is not missed.
  const int sub = 1 << std::max(0, spec.level - level);
  const double h = length / (b * sub);
  const int lo = -kGhost * sub, hi = (b + kGhost) * sub;
  const Vec3 extent = forest_.extent();
  for (int k = lo; k < hi; ++k)
    for (int j = lo; j < hi; ++j)
      for (int i = lo; i < hi; ++i) {
        Vec3 x{lower.x + (i + 0.5) * h, lower.y + (j + 0.5) * h, lower.z + (k + 0.5) * h};
        for (int d = 0; d < 3; ++d) {
          if (!spec.periodic[D(d)]) continue;
          if (x[d] < spec.origin[d]) x[d] += extent[d];
          if (x[d] >= spec.origin[d] + extent[d]) x[d] -= extent[d];
        }
        if (solid_function_(x)) return true;
      }
  return false;
}

std::int64_t NavierStokes::blocks_near_solids_below(int level) const {
  double count = 0.0;
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const Block& block = forest_.block(blk);
    if (block.level < level && near_solid(block.lower, block.length, block.level)) count += 1.0;
  }
  return static_cast<std::int64_t>(forest_.sum(count));
}

bool NavierStokes::keep_solids_finest(std::vector<AdaptFlag>& flags, int max_level) const {
  std::vector<char> near(flags.size(), 0);
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    near[static_cast<std::size_t>(blk)] = near_solid(block.lower, block.length, block.level);
  });
  double refine = 0.0;
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const Block& block = forest_.block(blk);
    AdaptFlag& flag = flags[static_cast<std::size_t>(blk)];
    if (near[static_cast<std::size_t>(blk)] != 0) {
      flag = block.level < max_level ? AdaptFlag::Refine : AdaptFlag::Keep;
      refine += flag == AdaptFlag::Refine ? 1.0 : 0.0;
    } else if (flag == AdaptFlag::Coarsen && block.level > 0) {  // tree roots never merge
      // The parent the family would merge into: its cells are twice as large,
      // so it reaches twice as far.
      Vec3 parent = block.lower;
      for (int d = 0; d < 3; ++d) {
        if (block.coord[D(d)] % 2 != 0) parent[d] -= block.length;
      }
      if (near_solid(parent, 2.0 * block.length, block.level - 1)) flag = AdaptFlag::Keep;
    }
  }
  return forest_.sum(refine) > 0.0;
}

void NavierStokes::close_solid_faces(FaceField& uf) const {
  if (!has_solids_) return;
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    for (int d = 0; d < 3; ++d) {
      const double* ob = open_[D(d)].block(blk);
      double* out = uf[D(d)].block(blk);
      for_each_face(b, d, [&](int i, int j, int k) {
        const std::ptrdiff_t c = solid_.layout().index(i, j, k);
        out[c] *= ob[c];
      });
    }
  });
}

void NavierStokes::clear_solid_cells(VectorField& u) const {
  if (!has_solids_) return;
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    for_each_cell(b, [&](int i, int j, int k) {
      if (solid_(blk, i, j, k) != 0.0) {
        for (auto& comp : u) comp(blk, i, j, k) = 0.0;
      }
    });
  });
}

Vec3 NavierStokes::solid_force() const {
  if (!has_solids_) return {};
  const int b = forest_.block_cells();
  const BlockLayout L = solid_.layout();
  Vec3 force{};
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const double h = forest_.block(blk).length / b;
    const double* sb = solid_.block(blk);
    for_each_cell(b, [&](int i, int j, int k) {
      const std::ptrdiff_t c = L.index(i, j, k);
      if (sb[c] != 0.0) return;
      for (int d = 0; d < 3; ++d) {
        for (int side = -1; side <= 1; side += 2) {
          if (sb[c + side * L.stride(d)] == 0.0) continue;
          // The pressure pushes into the solid; the wall shear drags it along
          // the fluid's tangential velocity (no-slip closure of the viscous step).
          force[d] += side * p_.block(blk)[c] * h * h;
          for (int e = 0; e < 3; ++e) {
            if (e != d) force[e] += mu_.block(blk)[c] * u_[D(e)].block(blk)[c] / (0.5 * h) * h * h;
          }
        }
      }
    });
  }
  return {forest_.sum(force.x), forest_.sum(force.y), forest_.sum(force.z)};
}

template <class Kernel>
void NavierStokes::for_each_block_with_velocity_ghosts(VectorField& u, int width,
                                                       VectorField* neumann, Kernel&& kernel) {
  if (!forest_.uniform_local()) {
    fill_velocity_ghosts(u, width);
    if (neumann) fill_neumann_ghosts(*neumann, 1);
    forest_.for_each_block(kernel);
    return;
  }
  // Each block's ghosts (copies of its neighbours' cells, then its boundary closures,
  // which read its own cells and ghosts) right before the kernel reads them: the values
  // fill_velocity_ghosts and fill_neumann_ghosts give, and the block's lines are in cache
  // when the kernel runs.
  BlockField* fields[] = {&u[0], &u[1], &u[2]};
  BlockField* others[] = {neumann ? &(*neumann)[0] : nullptr, neumann ? &(*neumann)[1] : nullptr,
                          neumann ? &(*neumann)[2] : nullptr};
  const auto neumann_kinds = uniform_kinds(forest_, BcKind::Neumann);
  forest_.for_each_block([&](int blk) {
    forest_.fill_same_level_ghosts(fields, blk, width, /*stencil_only=*/true);
    for (int c = 0; c < 3; ++c) {
      fill_block_boundary_ghosts(forest_, u[D(c)], blk, velocity_bc_[D(c)].kind,
                                 &velocity_bc_[D(c)].value, width);
    }
    if (neumann) {
      forest_.fill_same_level_ghosts(others, blk, 1);
      for (BlockField* f : others) {
        fill_block_boundary_ghosts(forest_, *f, blk, neumann_kinds, nullptr, 1);
      }
    }
    kernel(blk);
  });
}

void NavierStokes::fill_velocity_ghosts(VectorField& u, int width) {
  BlockField* fields[] = {&u[0], &u[1], &u[2]};
  forest_.exchange(fields, width);
  for (int c = 0; c < 3; ++c) fill_boundary_ghosts(forest_, u[D(c)], velocity_bc_[D(c)], width);
}

void NavierStokes::fill_scalar_neumann(BlockField& f, int width) {
  forest_.exchange(f, width);
  fill_boundary_ghosts(forest_, f, uniform_kinds(forest_, BcKind::Neumann), width);
}

void NavierStokes::fill_neumann_ghosts(VectorField& v, int width) {
  BlockField* fields[] = {&v[0], &v[1], &v[2]};
  forest_.exchange(fields, width);  // one exchange for the three
  const auto kinds = uniform_kinds(forest_, BcKind::Neumann);
  for (BlockField& f : v) fill_boundary_ghosts(forest_, f, kinds, width);
}

std::array<bool, 6> NavierStokes::prescribed_faces(const Block& block) const {
  std::array<bool, 6> prescribed{};
  for (int f = 0; f < 6; ++f) {
    const FlowBoundaryKind kind = boundaries_[D(f)].kind;
    prescribed[D(f)] = on_boundary(block, f / 2, f % 2) &&
                       (kind == FlowBoundaryKind::Wall || kind == FlowBoundaryKind::Inflow);
  }
  return prescribed;
}

double NavierStokes::inflow_face_mean(const FlowBoundary& inflow,
                                      const std::array<bool, 6>& prescribed, Vec3 x,
                                      const std::array<int, 3>& cell, int d, double h) const {
  // The face mean of the profile, as face_mean gives the interior faces: the
  // centre value plus 1/24 of the transverse second differences, left out
  // (as there) beside a wall or another inflow, where the profile need not
  // extend smoothly; across a periodic seam the profile is taken one period
  // over, so it is only read inside the domain.
  const auto profile = [&](const Vec3& at) {
    return inflow.inflow(wrap_periodic(forest_, at), bc_time_)[d];
  };
  const double centre = profile(x);
  double second_differences = 0.0;
  for (int t = 0; t < 3; ++t) {
    if (t == d || beside_prescribed(prescribed, t, cell[D(t)], forest_.block_cells())) continue;
    Vec3 step{};
    step[t] = h;
    second_differences += profile(x + step) - 2.0 * centre + profile(x - step);
  }
  return centre + second_differences / 24.0;
}

void NavierStokes::set_boundary_faces(FaceField& uf) const {
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    const std::array<bool, 6> prescribed = prescribed_faces(block);
    for (int d = 0; d < 3; ++d) {
      for (int side = 0; side < 2; ++side) {
        const FlowBoundary& fb = boundaries_[D(face_index(d, side))];
        if (!prescribed[D(face_index(d, side))]) continue;
        for (int t2 = 0; t2 < b; ++t2)
          for (int t1 = 0; t1 < b; ++t1) {
            std::array<int, 3> idx{};
            idx[D(d)] = side == 0 ? 0 : b;
            idx[D((d + 1) % 3)] = t1;
            idx[D((d + 2) % 3)] = t2;
            double value = fb.wall_velocity[d];
            if (fb.kind == FlowBoundaryKind::Inflow) {
              Vec3 x{};
              for (int e = 0; e < 3; ++e) x[e] = block.lower[e] + (idx[D(e)] + 0.5) * h;
              x[d] = block.lower[d] + idx[D(d)] * h;
              value = inflow_face_mean(fb, prescribed, x, idx, d, h);
            }
            uf[D(d)](blk, idx[0], idx[1], idx[2]) = value;
          }
      }
    }
  });
}

void NavierStokes::fill_face_ghosts(FaceField& uf) {
  BlockField* fields[] = {&uf[0], &uf[1], &uf[2]};
  // The upper faces (slot b, in the ghost layer) are the block's own: the
  // exchange copies the same face from a neighbour of the same level, but
  // across a level jump it would interpolate face values as if they were
  // cells. Composite grids keep them.
  std::vector<double> upper;
  const int b = forest_.block_cells();
  const BlockLayout L = uf[0].layout();
  auto for_upper_faces = [&](auto&& body) {
    std::size_t at = 0;
    for (int blk = 0; blk < forest_.local_blocks(); ++blk)
      for (int d = 0; d < 3; ++d)
        for_face_layer(
            L, d, 1, [&](std::ptrdiff_t, std::ptrdiff_t f) { body(uf[D(d)].block(blk)[f], at++); });
  };
  if (composite_) {
    upper.resize(static_cast<std::size_t>(forest_.local_blocks()) * 3 * D(b) * D(b));
    for_upper_faces([&](double& face, std::size_t at) { upper[at] = face; });
  }
  forest_.exchange(fields, kGhost);
  fill_face_field_ghosts(forest_, uf, kGhost);
  if (composite_) for_upper_faces([&](double& face, std::size_t at) { face = upper[at]; });
}

void NavierStokes::synchronise_coarse_faces(FaceField& uf) {
  if (!composite_) return;
  send_faces(forest_, interface_, LevelJump::Coarser,
             [&](int blk, int d, std::ptrdiff_t f) { return uf[D(d)].block(blk)[f]; });
  forest_.for_each_block([&](int blk) {
    for_received_faces(
        forest_, interface_, blk, LevelJump::Finer,
        [&](int d, int, std::ptrdiff_t f, double mean) { uf[D(d)].block(blk)[f] = mean; });
  });
}

double NavierStokes::stable_dt() const {
  const double rate = max_face_rate();
  const double dt = rate > 0.0 ? std::min(options_.dt_max, options_.cfl / rate) : options_.dt_max;
  if (!std::isfinite(dt)) {
    throw std::invalid_argument("navier-stokes: fluid at rest and no maximum time step given");
  }
  return dt;
}

void NavierStokes::predict_face_velocity(double dt) {
  const int b = forest_.block_cells();
  const BlockLayout L = u_[0].layout();
  const Strides s{L.stride(0), L.stride(1), L.stride(2)};
  for_each_block_with_velocity_ghosts(u_, kGhost, &g_, [&](int blk) {
    const StepScales scales = step_scales(forest_, options_.level_matched_advection, blk, dt);
    const bool matched = scales.finest_h < scales.h;
    const std::array<const double*, 3> u{u_[0].block(blk), u_[1].block(blk), u_[2].block(blk)};
    for (int d = 0; d < 3; ++d) {
      const double* f = u[D(d)];
      const double* src = g_[D(d)].block(blk);
      double* out = uf_[D(d)].block(blk);
      const std::ptrdiff_t sd = s[D(d)];
      // bcg_face_value with the cell velocities: un the mean of the two
      // cells, the transverse velocities the upwind cell's.
      auto along = [&]<int Dir>(std::integral_constant<int, Dir>) {
        const int ni = Dir == 0 ? b + 1 : b, nj = Dir == 1 ? b + 1 : b, nk = Dir == 2 ? b + 1 : b;
        with_level_matching(matched, [&]<bool Matched>(std::bool_constant<Matched>) {
          for (int k = 0; k < nk; ++k)
            for (int j = 0; j < nj; ++j)
              bcg_face_row<Dir, Matched>(
                  f, L.index(0, j, k), ni, s, scales,
                  [&](std::ptrdiff_t c) { return 0.5 * (f[c] + f[c - sd]); },
                  [&](int e, std::ptrdiff_t q) { return u[D(e)][q]; },
                  [&](std::ptrdiff_t c) { return 0.25 * dt * (src[c] + src[c - sd]); },
                  [&](std::ptrdiff_t c, double value, double) { out[c] = value; });
        });
      };
      if (d == 0) along(std::integral_constant<int, 0>{});
      if (d == 1) along(std::integral_constant<int, 1>{});
      if (d == 2) along(std::integral_constant<int, 2>{});
    }
  });
  set_boundary_faces(uf_);
  close_solid_faces(uf_);
}

void NavierStokes::advect(double dt) {
  for (int comp = 0; comp < 3; ++comp) {
    advect_field(u_[D(comp)], &g_[D(comp)], velocity_bc_[D(comp)].kind, scratch_[D(comp)], dt);
  }
}

void NavierStokes::advect_scalar(BlockField& c, double dt) {
  if (c.blocks() != forest_.local_blocks() || c.cells() != forest_.block_cells()) {
    throw std::invalid_argument(
        "navier-stokes: advect_scalar: the field does not match the forest's blocks (pass "
        "tracers to regrid() so that they follow the grid)");
  }
  fill_scalar_neumann(c, kGhost);
  fill_face_ghosts(uf_);
  set_boundary_faces(uf_);
  BlockField out(forest_.local_blocks(), forest_.block_cells());
  advect_field(c, nullptr, uniform_kinds(forest_, BcKind::Neumann), out, dt);
  const int b = forest_.block_cells();
  forest_.for_each_block([&](int blk) {
    for_each_cell(b, [&](int i, int j, int k) { c(blk, i, j, k) = out(blk, i, j, k); });
  });
}

template <typename BlockFluxes, typename UpperFlux, typename Update>
void NavierStokes::update_from_face_fluxes(BlockFluxes&& block_fluxes, UpperFlux&& upper_flux,
                                           Update&& update) {
  const BlockLayout L = u_[0].layout();
  if (!composite_) {
    forest_.for_each_block([&](int blk) {
      // Face fluxes of one block, per direction: scratch kept per thread.
      thread_local std::array<std::vector<double>, 3> flux;
      for (int d = 0; d < 3; ++d) {
        flux[D(d)].resize(static_cast<std::size_t>(L.size()));
        block_fluxes(blk, d, flux[D(d)].data());
      }
      update(blk, std::array<const double*, 3>{flux[0].data(), flux[1].data(), flux[2].data()});
    });
    return;
  }
  // Composite grids: each face's flux is computed once and used by both
  // cells beside it (conservation to round-off, §4.3.1). Two blocks of one
  // level would otherwise each evaluate their shared face with their own
  // ghosts, which differ where a coarser block lies beyond an edge (face
  // velocities interpolated as if they were cells): the upper block's face 0
  // wins and reaches the lower block's slot b by the exchange. At coarse-fine
  // faces the fine faces win: the coarse face takes the mean of the 4.
  forest_.for_each_block([&](int blk) {
    for (int d = 0; d < 3; ++d) block_fluxes(blk, d, face_flux_[D(d)].block(blk));
  });
  send_faces(forest_, interface_, LevelJump::Coarser,
             [&](int blk, int d, std::ptrdiff_t f) { return face_flux_[D(d)].block(blk)[f]; });
  BlockField* fluxes[] = {&face_flux_[0], &face_flux_[1], &face_flux_[2]};
  forest_.exchange(fluxes, 1, true);
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    for (int d = 0; d < 3; ++d) {
      double* fl = face_flux_[D(d)].block(blk);
      const Neighbour& upper = block.neighbours[face_neighbour_slot(d, 1)];
      // The exchange only brings a same-level neighbour's face 0; a domain
      // boundary or a coarser neighbour leaves slot b to this block.
      if (upper.link == Link::Boundary || upper.jump == LevelJump::Coarser) {
        for_face_layer(L, d, 1,
                       [&](std::ptrdiff_t, std::ptrdiff_t f) { fl[f] = upper_flux(blk, d, f); });
      }
    }
    for_received_faces(forest_, interface_, blk, LevelJump::Finer,
                       [&](int d, int, std::ptrdiff_t face, double mean) {
                         face_flux_[D(d)].block(blk)[face] = mean;
                       });
    update(blk, std::array<const double*, 3>{face_flux_[0].block(blk), face_flux_[1].block(blk),
                                             face_flux_[2].block(blk)});
  });
}

void NavierStokes::advect_field(const BlockField& field, const BlockField* source,
                                const std::array<BcKind, 6>& kinds, BlockField& out, double dt) {
  const int b = forest_.block_cells();
  const BlockLayout L = field.layout();
  const Strides s{L.stride(0), L.stride(1), L.stride(2)};
  // One block's arrays and cell size, read once per block: per face, the
  // compiler reloads them (the flux stores may alias them), and the cell
  // size costs a division.
  struct BlockView {
    const double* f;
    const double* src;
    std::array<const double*, 3> uf;
    StepScales scales;
  };
  auto view = [&](int blk) {
    return BlockView{field.block(blk),
                     source ? source->block(blk) : nullptr,
                     {uf_[0].block(blk), uf_[1].block(blk), uf_[2].block(blk)},
                     step_scales(forest_, options_.level_matched_advection, blk, dt)};
  };
  // BCG value times the face velocity on face c (number n along d) of a
  // block; dirichlet_lo/hi: the block's d-faces 0/b carry a boundary value.
  auto face_flux = [&](const BlockView& v, int d, std::ptrdiff_t c, int n, bool dirichlet_lo,
                       bool dirichlet_hi) {
    const double* f = v.f;
    const double un = v.uf[D(d)][c];
    double value;
    if (n == 0 && dirichlet_lo) {
      // The boundary value itself, from the quadratic ghost closure.
      value = (3.0 * f[c - s[D(d)]] + 6.0 * f[c] - f[c + s[D(d)]]) / 8.0;
    } else if (n == b && dirichlet_hi) {
      value = (3.0 * f[c] + 6.0 * f[c - s[D(d)]] - f[c - 2 * s[D(d)]]) / 8.0;
    } else {
      const std::ptrdiff_t up = un > 0.0 ? c - s[D(d)] : c;
      std::array<double, 3> vt{};
      for (int e = 0; e < 3; ++e) vt[D(e)] = 0.5 * (v.uf[D(e)][up] + v.uf[D(e)][up + s[D(e)]]);
      const double src = v.src ? 0.25 * dt * (v.src[c] + v.src[c - s[D(d)]]) : 0.0;
      value = bcg_face_value(f, src, un, v.scales, d, c, s, vt);
    }
    return value * un;
  };
  // Fluxes of all faces 0..b of one block along d into fl; the direction a
  // compile-time constant, so that the strides along it are known.
  auto fluxes_along = [&]<int Dir>(std::integral_constant<int, Dir>, int blk, double* fl) {
    const Block& block = forest_.block(blk);
    const bool dirichlet_lo =
        on_boundary(block, Dir, 0) && kinds[D(face_index(Dir, 0))] == BcKind::Dirichlet;
    const bool dirichlet_hi =
        on_boundary(block, Dir, 1) && kinds[D(face_index(Dir, 1))] == BcKind::Dirichlet;
    const BlockView v = view(blk);
    const std::ptrdiff_t sd = s[D(Dir)];
    const double* un = v.uf[D(Dir)];
    const bool has_source = v.src != nullptr;
    const double* src = has_source ? v.src : v.f;  // v.f: read, then not used
    const int ni = Dir == 0 ? b + 1 : b, nj = Dir == 1 ? b + 1 : b, nk = Dir == 2 ? b + 1 : b;
    const bool matched = v.scales.finest_h < v.scales.h;
    with_level_matching(matched, [&]<bool Matched>(std::bool_constant<Matched>) {
      for (int k = 0; k < nk; ++k)
        for (int j = 0; j < nj; ++j) {
          const std::ptrdiff_t row = L.index(0, j, k);
          // The interior faces in one branch-free pass (face_flux's last case)...
          bcg_face_row<Dir, Matched>(
              v.f, row, ni, s, v.scales, [&](std::ptrdiff_t c) { return un[c]; },
              [&](int e, std::ptrdiff_t q) {
                return 0.5 * (v.uf[D(e)][q] + v.uf[D(e)][q + s[D(e)]]);
              },
              [&](std::ptrdiff_t c) {
                const double term = 0.25 * dt * (src[c] + src[c - sd]);  // loaded either way
                return has_source ? term : 0.0;
              },
              [&](std::ptrdiff_t c, double value, double u) { fl[c] = value * u; });
          // ... then the faces on a Dirichlet boundary again, by face_flux.
          const int n_row = Dir == 1 ? j : k;  // the face number along Dir, rows of y or z faces
          for (int side = 0; side < 2; ++side) {
            const int face = side == 0 ? 0 : b;
            if (!(side == 0 ? dirichlet_lo : dirichlet_hi)) continue;
            if (Dir == 0) {
              fl[row + face] = face_flux(v, Dir, row + face, face, dirichlet_lo, dirichlet_hi);
            } else if (n_row == face) {
              for (int i = 0; i < b; ++i)
                fl[row + i] = face_flux(v, Dir, row + i, face, dirichlet_lo, dirichlet_hi);
            }
          }
        }
    });
  };
  auto block_fluxes = [&](int blk, int d, double* fl) {
    if (d == 0) fluxes_along(std::integral_constant<int, 0>{}, blk, fl);
    if (d == 1) fluxes_along(std::integral_constant<int, 1>{}, blk, fl);
    if (d == 2) fluxes_along(std::integral_constant<int, 2>{}, blk, fl);
  };
  // out = f - dt div(flux) / h on one block.
  auto update = [&](int blk, const std::array<const double*, 3>& flux) {
    const double h = forest_.block(blk).length / b;
    const double* f = field.block(blk);
    double* o = out.block(blk);
    for_each_cell(b, [&](int i, int j, int k) {
      const std::ptrdiff_t c = L.index(i, j, k);
      double div = 0.0;
      for (int d = 0; d < 3; ++d) div += flux[D(d)][c + s[D(d)]] - flux[D(d)][c];
      o[c] = f[c] - dt * div / h;
    });
  };
  update_from_face_fluxes(
      block_fluxes,
      [&](int blk, int d, std::ptrdiff_t f) {
        const bool dirichlet_hi = on_boundary(forest_.block(blk), d, 1) &&
                                  kinds[D(face_index(d, 1))] == BcKind::Dirichlet;
        return face_flux(view(blk), d, f, b, false, dirichlet_hi);
      },
      update);
}

void NavierStokes::fill_viscosity_ghosts() {
  if (viscosity_changed_) {  // on every rank: the writers of mu mark it on all of them
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
      for_each_cell(forest_.block_cells(), [&](int i, int j, int k) {
        lo = std::min(lo, mu_(blk, i, j, k));
        hi = std::max(hi, mu_(blk, i, j, k));
      });
    }
    viscosity_range_ = {-forest_.max(-lo), forest_.max(hi)};
    variable_viscosity_ = viscosity_range_[1] > viscosity_range_[0];
  }
  fill_scalar_neumann(mu_, 1);
  if (!composite_ || !variable_viscosity_) return;
  // Ghosts across coarse-fine faces are quadratic interpolants of the coarse
  // cells: next to a jump they overshoot (a 1 : 5 jump gives a negative
  // ghost, hence a negative harmonic face viscosity, anti-diffusion and a
  // multigrid operator that is no longer definite). Clamped to the field's
  // range they stay positive; same-level and boundary ghosts are copies and
  // already in it.
  const int b = forest_.block_cells();
  const BlockLayout L = mu_.layout();
  const double lo = viscosity_range_[0], hi = viscosity_range_[1];
  forest_.for_each_block([&](int blk) {
    double* mu = mu_.block(blk);
    for (int k = -1; k <= b; ++k)
      for (int j = -1; j <= b; ++j)
        for (int i = -1; i <= b; ++i) {
          double& m = mu[L.index(i, j, k)];
          m = std::clamp(m, lo, hi);
        }
  });
}

void NavierStokes::update_viscous_coefficients(double dt) {
  // mu's ghosts stay valid until mu changes (every writer marks it, see
  // viscosity()): the explicit viscous fluxes read them at every step, but
  // they are refilled only with the coefficients.
  if (dt == viscous_dt_ && !viscosity_changed_) return;
  fill_viscosity_ghosts();
  const int n = forest_.local_blocks();
  const int b = forest_.block_cells();
  BlockField alpha(n, b);
  alpha.fill(1.0);
  FaceField beta = make_vector_field(n, b);
  const double scale = options_.viscous_theta * dt / fluid_.density;
  forest_.for_each_block([&](int blk) {
    const BlockLayout L = mu_.layout();
    const double* mu = mu_.block(blk);
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t s = L.stride(d);
      const double* open = open_[D(d)].block(blk);
      double* out = beta[D(d)].block(blk);
      for_each_face(b, d, [&](int i, int j, int k) {
        const std::ptrdiff_t c = L.index(i, j, k);
        out[c] = open[c] * scale * face_viscosity(mu[c], mu[c - s]);
      });
    }
    if (!has_solids_) return;
    // No-slip on the faces of solid cells: a fluid cell there gets the wall
    // flux 2 mu (0 - u)/h implicitly (alpha), the solid cell keeps u = 0.
    const double h = forest_.block(blk).length / b;
    for_each_cell(b, [&](int i, int j, int k) {
      const std::ptrdiff_t c = L.index(i, j, k);
      if (solid_.block(blk)[c] != 0.0) return;
      double walls = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double* open = open_[D(d)].block(blk);
        walls += (1.0 - open[c]) + (1.0 - open[c + L.stride(d)]);
      }
      alpha.block(blk)[c] += walls * 2.0 * scale * mu[c] / (h * h);
    });
  });
  viscous_mg_->set_coefficients(&alpha, &beta);
  viscous_dt_ = dt;
  viscosity_changed_ = false;
}

void NavierStokes::add_viscous_fluxes(double laplacian_weight, bool transpose, double factor,
                                      VectorField& out) {
  // For component i the flux through a d-face is
  //   mu_f [laplacian_weight du_i/dx_d + du_d/dx_i (if transpose)]
  // with mu_f the harmonic mean of the two cells; out_i += factor div(flux) in
  // every cell. On composite grids the coarse face takes the fine faces'
  // mean like every other flux (momentum conserved across coarse-fine faces).
  // The velocity's ghosts and mu's (width 1) must be filled.
  const int b = forest_.block_cells();
  const BlockLayout L = u_[0].layout();
  for (int i = 0; i < 3; ++i) {
    const std::ptrdiff_t si = L.stride(i);
    // Flux of component i through the d-face f of a block.
    auto flux = [&](int blk, int d, std::ptrdiff_t f) {
      const double h = forest_.block(blk).length / b;
      const std::ptrdiff_t sd = L.stride(d);
      const double* mu = mu_.block(blk);
      double gradient = 0.0;
      if (laplacian_weight != 0.0) {
        const double* ui = u_[D(i)].block(blk);
        gradient += laplacian_weight * (ui[f] - ui[f - sd]) / h;
      }
      if (transpose) {
        const double* ud = u_[D(d)].block(blk);
        gradient +=
            i == d ? (ud[f] - ud[f - sd]) / h
                   : ((ud[f + si] - ud[f - si]) + (ud[f - sd + si] - ud[f - sd - si])) / (4.0 * h);
      }
      return open_[D(d)].block(blk)[f] * face_viscosity(mu[f], mu[f - sd]) * gradient;
    };
    auto block_fluxes = [&](int blk, int d, double* fl) {
      for_each_face(b, d, [&](int x, int y, int z) {
        const std::ptrdiff_t f = L.index(x, y, z);
        fl[f] = flux(blk, d, f);
      });
    };
    auto update = [&](int blk, const std::array<const double*, 3>& fl) {
      const double h = forest_.block(blk).length / b;
      const double* mu = mu_.block(blk);
      const double* ui = u_[D(i)].block(blk);
      const double* solid = solid_.block(blk);
      double* o = out[D(i)].block(blk);
      for_each_cell(b, [&](int x, int y, int z) {
        const std::ptrdiff_t c = L.index(x, y, z);
        double sum = 0.0, walls = 0.0;
        for (int d = 0; d < 3; ++d) {
          const std::ptrdiff_t sd = L.stride(d);
          sum += fl[D(d)][c + sd] - fl[D(d)][c];
          walls += (1.0 - open_[D(d)].block(blk)[c]) + (1.0 - open_[D(d)].block(blk)[c + sd]);
        }
        // No-slip faces of solid neighbours: the wall flux 2 mu (0 - u_i)/h.
        if (solid[c] == 0.0) sum -= laplacian_weight * walls * 2.0 * mu[c] * ui[c] / h;
        o[c] += factor * sum / h;
      });
    };
    update_from_face_fluxes(block_fluxes, flux, update);
  }
}

VectorField NavierStokes::viscous_force_density() {
  fill_velocity_ghosts(u_);
  fill_viscosity_ghosts();
  VectorField force = make_vector_field(forest_.local_blocks(), forest_.block_cells());
  add_viscous_fluxes(1.0, true, 1.0, force);
  return force;
}

void NavierStokes::viscous_step(double dt, StepReport& report) {
  const int b = forest_.block_cells();
  const double theta = options_.viscous_theta;
  update_viscous_coefficients(dt);
  // The explicit parts of the viscous term of eq. 4.1, with u^n (its ghosts
  // are still filled), added to u*: (1 - theta) div(mu grad u) for
  // Crank-Nicolson, and div(mu grad u^T), which vanishes for uniform mu
  // (div(grad u^T) = grad div u = 0) and is skipped there.
  if (theta < 1.0 || variable_viscosity_) {
    add_viscous_fluxes(1.0 - theta, variable_viscosity_, dt / fluid_.density, scratch_);
  }
  // face_average_plus_acceleration() fills u's ghosts before they are read.
  MultigridOptions solve_options = options_.viscous;
  solve_options.fill_ghosts_on_return = false;
  for (int comp = 0; comp < 3; ++comp) {
    BlockField& rhs = scratch_[D(comp)];
    BlockField& u = u_[D(comp)];
    const BlockField& g = g_[D(comp)];
    // Warm start: the right-hand side plus the last step's viscous
    // increment, which changes little from step to step (64^3 cavity: 5.4
    // V-cycles per step for the three solves from the right-hand side alone,
    // 2.8 with the increment).
    BlockField& increment = viscous_increment_[D(comp)];
    const BlockLayout L = u.layout();
    forest_.for_each_block([&](int blk) {
      double* rb = rhs.block(blk);
      double* ub = u.block(blk);
      const double* gb = g.block(blk);
      const double* ib = increment.block(blk);
      for_each_row(L, [&](std::ptrdiff_t row, int, int) {
        for (std::ptrdiff_t c = row; c < row + b; ++c) {
          rb[c] += dt * gb[c];
          ub[c] = rb[c] + ib[c];
        }
      });
    });
    const auto r = viscous_mg_->solve(u, rhs, velocity_bc_[D(comp)], solve_options);
    report.viscous_cycles += r.cycles;
    if (!r.converged) {
      std::ostringstream what;
      what << "navier-stokes: viscous solve did not converge: RMS residual " << r.residuals.front()
           << " -> " << r.residuals.back() << " in " << r.cycles << " V-cycles, RMS rhs "
           << r.rhs_norm;
      throw SimulationError(what.str());
    }
    forest_.for_each_block([&](int blk) {
      const double* rb = rhs.block(blk);
      double* ub = u.block(blk);
      const double* gb = g.block(blk);
      double* ib = increment.block(blk);
      for_each_row(L, [&](std::ptrdiff_t row, int, int) {
        for (std::ptrdiff_t c = row; c < row + b; ++c) {
          ib[c] = ub[c] - rb[c];
          ub[c] -= dt * gb[c];
        }
      });
    });
  }
}

namespace {

/// face_average_plus_acceleration's faces along d of one block without
/// solids, row by row: the stencil's flags change along a row only at its
/// ends (the faces within two cells of a prescribed face along d when d = x,
/// the cells beside a prescribed face across x otherwise), so each row is
/// cut into spans of constant flags and each span runs as one vector loop.
/// Same flags, same operations per face as the loop over faces: the same bits.
/// Needs b >= 4 (the spans of a row do not overlap).
void face_average_rows(int d, int b, const BlockLayout& L, const Strides& s,
                       const std::array<bool, 6>& prescribed, const double* u, const double* a,
                       double* out, double dt) {
  const auto spans = [&]<int kD>(std::integral_constant<int, kD>) {
    const int nj = kD == 1 ? b + 1 : b, nk = kD == 2 ? b + 1 : b;
    const bool lo_x = prescribed[D(face_index(0, 0))], hi_x = prescribed[D(face_index(0, 1))];
    for (int k = 0; k < nk; ++k)
      for (int j = 0; j < nj; ++j) {
        const std::ptrdiff_t row = L.index(0, j, k);
        const std::array<int, 3> n{0, j, k};
        // What face_average_plus_acceleration decides per face, for (j, k).
        const auto normal_at = [&](int along) {
          return !(along <= 1 && prescribed[D(face_index(kD, 0))]) &&
                 !(along >= b - 1 && prescribed[D(face_index(kD, 1))]);
        };
        bool across_yz = true;  // the transverse flag's part from y and z
        for (int t = 1; t < 3; ++t) {
          if (t != kD) across_yz = across_yz && !beside_prescribed(prescribed, t, n[D(t)], b);
        }
        if constexpr (kD == 0) {
          // Faces i = 0..b; the cubic stencil is off within two cells of a prescribed x face.
          const bool lo = normal_at(0), hi = normal_at(b);
          face_means_in_row<0>(out, u, a, row, 2, s, dt, lo, across_yz);
          face_means_in_row<0>(out, u, a, row + 2, b - 3, s, dt, true, across_yz);
          face_means_in_row<0>(out, u, a, row + b - 1, 2, s, dt, hi, across_yz);
        } else {
          // Cells i = 0..b-1; the transverse correction is off beside a prescribed x face.
          const bool cubic = normal_at(n[D(kD)]);
          face_means_in_row<kD>(out, u, a, row, 1, s, dt, cubic, across_yz && !lo_x);
          face_means_in_row<kD>(out, u, a, row + 1, b - 2, s, dt, cubic, across_yz);
          face_means_in_row<kD>(out, u, a, row + b - 1, 1, s, dt, cubic, across_yz && !hi_x);
        }
      }
  };
  if (d == 0) spans(std::integral_constant<int, 0>{});
  if (d == 1) spans(std::integral_constant<int, 1>{});
  if (d == 2) spans(std::integral_constant<int, 2>{});
}

}  // namespace

void NavierStokes::face_average_plus_acceleration(double dt) {
  const int b = forest_.block_cells();
  const BlockLayout L = u_[0].layout();
  const Strides s{L.stride(0), L.stride(1), L.stride(2)};
  for_each_block_with_velocity_ghosts(u_, 2, nullptr, [&](int blk) {
    const std::array<bool, 6> prescribed = prescribed_faces(forest_.block(blk));
    const double* solid = solid_.block(blk);
    for (int d = 0; d < 3; ++d) {
      // u here lacks the pressure gradient (u* of the projection), so it
      // breaks its own wall condition by dt g: the ghosts of a wall or an
      // inflow, closed on the wall value, make a kink there. face_mean's
      // stencil stays off them: the plain average along d within two cells
      // of such a face, no transverse correction in the cells beside one.
      const double* u = u_[D(d)].block(blk);
      const double* a = accel_[D(d)].block(blk);
      double* out = uf_[D(d)].block(blk);
      if (!has_solids_ && b >= 4) {
        face_average_rows(d, b, L, s, prescribed, u, a, out, dt);
        continue;
      }
      for_each_face(b, d, [&](int i, int j, int k) {
        const std::array<int, 3> n{i, j, k};
        const std::ptrdiff_t c = L.index(i, j, k);
        bool normal = !(n[D(d)] <= 1 && prescribed[D(face_index(d, 0))]) &&
                      !(n[D(d)] >= b - 1 && prescribed[D(face_index(d, 1))]);
        bool transverse = true;
        for (int t = 0; t < 3; ++t) {
          if (t != d) transverse = transverse && !beside_prescribed(prescribed, t, n[D(t)], b);
        }
        // Beside solids (u = 0 in them) the plain average; the closure follows.
        if (has_solids_ && !face_mean_stencil_is_fluid(solid, d, c, s)) normal = transverse = false;
        out[c] = face_mean(u, d, c, s, normal, transverse) + dt * a[c];
      });
    }
  });
  set_boundary_faces(uf_);
  close_solid_faces(uf_);
}

double NavierStokes::max_face_rate() const {
  // Per block max |uf|, then one division: division is monotonic, so this is
  // the max of |uf| / h over the faces to the last bit.
  const int b = forest_.block_cells();
  const BlockLayout L = uf_[0].layout();
  double rate = 0.0;
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    double largest = 0.0;
    for (int d = 0; d < 3; ++d) {
      const double* uf = uf_[D(d)].block(blk);
      for_each_face(b, d, [&](int i, int j, int k) {
        largest = std::max(largest, std::abs(uf[L.index(i, j, k)]));
      });
    }
    rate = std::max(rate, largest / (forest_.block(blk).length / b));
  }
  return forest_.max(rate);
}

MultigridReport NavierStokes::project(BlockField& phi) {
  // eq. 4.2 discretely: div(grad phi) = div uf, then uf -= grad phi.
  const int b = forest_.block_cells();
  const BlockLayout L = phi.layout();
  BlockField& rhs = scratch_[0];
  // Composite grids: the divergence of a coarse cell beside finer blocks
  // takes the fine faces' flux (their mean), as the composite operator does.
  synchronise_coarse_faces(uf_);
  // The same pass takes each block's max |uf| over its faces 0..b, for the
  // tolerance floor below: max_face_rate() without a second pass (a max, so
  // the same value in any order).
  const std::ptrdiff_t sy = L.stride(1), sz = L.stride(2);
  block_face_rate_.resize(static_cast<std::size_t>(forest_.local_blocks()));
  forest_.for_each_block([&](int blk) {
    const double h = forest_.block(blk).length / b;
    const double* ux = uf_[0].block(blk);
    const double* uy = uf_[1].block(blk);
    const double* uz = uf_[2].block(blk);
    double* out = rhs.block(blk);
    // |x| as its bits: for doubles >= 0 the unsigned order of the bits is
    // the order of the values, and an integer max vectorises where a
    // floating-point one (NaN rules) does not. A NaN would win here (and
    // leave the floor below at options.absolute_tolerance); the solve then
    // fails on its NaN residual.
    const auto magnitude = [](double x) {
      return std::bit_cast<std::uint64_t>(x) & ~(std::uint64_t{1} << 63);
    };
    std::uint64_t largest = 0;
    for_each_row(L, [&](std::ptrdiff_t row, int, int) {
      for (std::ptrdiff_t c = row; c < row + b; ++c) {
        double div = 0.0;
        div += ux[c + 1] - ux[c];
        div += uy[c + sy] - uy[c];
        div += uz[c + sz] - uz[c];
        out[c] = -div / h;
        const std::uint64_t m =
            std::max({magnitude(ux[c]), magnitude(ux[c + 1]), magnitude(uy[c]),
                      magnitude(uy[c + sy]), magnitude(uz[c]), magnitude(uz[c + sz])});
        largest = std::max(largest, m);
      }
    });
    block_face_rate_[static_cast<std::size_t>(blk)] = std::bit_cast<double>(largest) / h;
  });
  double rate = 0.0;
  for (const double r : block_face_rate_) rate = std::max(rate, r);
  // A floor above round-off: |div uf| ~ 1e-12 max|uf|/h is exact enough.
  MultigridOptions options = options_.pressure;
  options.absolute_tolerance = std::max(options.absolute_tolerance, 1e-12 * forest_.max(rate));
  MultigridReport report = pressure_mg_->solve(phi, rhs, pressure_bc_, options);
  if (!report.converged) {
    std::ostringstream what;
    what << "navier-stokes: projection did not converge: RMS residual " << report.residuals.front()
         << " -> " << report.residuals.back() << " in " << report.cycles << " V-cycles, RMS rhs "
         << report.rhs_norm << ", tolerance " << options_.pressure.tolerance;
    throw SimulationError(what.str());
  }
  // Composite grids: the ghosts of phi as the composite operator sees them
  // (quadratic interpolation in fine ghosts, matched fluxes in coarse ones),
  // so that the correction below subtracts exactly the fluxes whose
  // divergence the multigrid drove to its residual.
  if (composite_) pressure_mg_->residual(phi, rhs, pressure_bc_, scratch_[2]);
  forest_.for_each_block([&](int blk) {
    const double h = forest_.block(blk).length / b;
    const double* pb = phi.block(blk);
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t s = L.stride(d);
      double* out = uf_[D(d)].block(blk);
      const double* open = open_[D(d)].block(blk);
      for_each_face(b, d, [&](int i, int j, int k) {
        const std::ptrdiff_t c = L.index(i, j, k);
        out[c] -= open[c] * (pb[c] - pb[c - s]) / h;
      });
    }
  });
  // The matched coarse ghosts already give the mean fine correction; this
  // makes the coarse faces the fine faces' mean to the last bit.
  synchronise_coarse_faces(uf_);
  return report;
}

StepReport NavierStokes::step(double dt) {
  if (!(dt > 0.0)) throw std::invalid_argument("navier-stokes: dt must be > 0");
  StepReport report;
  report.dt = dt;
  const int b = forest_.block_cells();
  const double rho = fluid_.density;
  bc_time_ = time_ + dt;

  // 1. prediction of the face velocity at t + dt/2 (it fills the ghosts of u and g, which
  // the advection below reads too), MAC projection with dt/2.
  predict_face_velocity(dt);
  // The predicted uf already holds -grad p through g (eq. 4.2 at t + dt/2),
  // so this projection finds only a correction: the previous step's
  // correction is its warm start (p itself, used before, is far from it:
  // 3.9 V-cycles per step against 1.3 on the 64^3 cavity).
  BlockField& predictor_phi = scratch_[1];
  forest_.for_each_block([&](int blk) {
    for_each_cell(b, [&](int i, int j, int k) {
      predictor_phi(blk, i, j, k) = predictor_p_(blk, i, j, k) * 0.5 * dt / rho;
    });
  });
  report.predictor_cycles = project(predictor_phi).cycles;
  forest_.for_each_block([&](int blk) {
    for_each_cell(b, [&](int i, int j, int k) {
      predictor_p_(blk, i, j, k) = predictor_phi(blk, i, j, k) * 2.0 * rho / dt;
    });
  });
  fill_face_ghosts(uf_);
  set_boundary_faces(uf_);

  // 2. advection u* = u - dt div(uf u_{n+1/2}).
  advect(dt);

  // 3. implicit viscosity.
  bool viscous = false;
  for (int blk = 0; blk < forest_.local_blocks() && !viscous; ++blk) {
    const double* mu = mu_.block(blk);
    for_each_row(mu_.layout(), [&](std::ptrdiff_t row, int, int) {
      for (std::ptrdiff_t c = row; c < row + b; ++c) viscous |= mu[c] != 0.0;
    });
  }
  viscous = forest_.max(viscous ? 1.0 : 0.0) > 0.0;
  if (viscous) {
    viscous_step(dt, report);
  } else {
    for (int c = 0; c < 3; ++c) u_[D(c)] = scratch_[D(c)];
  }

  // 4. face velocity with the body force, 5. projection.
  face_average_plus_acceleration(dt);
  BlockField& phi = scratch_[1];
  forest_.for_each_block([&](int blk) {
    for_each_cell(b, [&](int i, int j, int k) { phi(blk, i, j, k) = p_(blk, i, j, k) * dt / rho; });
  });
  pressure_report_ = project(phi);
  report.pressure_cycles = pressure_report_.cycles;
  report.pressure_reduction = pressure_report_.mean_reduction();
  const BlockLayout L = p_.layout();
  forest_.for_each_block([&](int blk) {
    const Block& block = forest_.block(blk);
    const double h = block.length / b;
    const double h_dt = h * dt;
    const double* pb = phi.block(blk);
    double* p_out = p_.block(blk);
    for_each_row(L, [&](std::ptrdiff_t row, int, int) {
      for (std::ptrdiff_t c = row; c < row + b; ++c) p_out[c] = pb[c] * rho / dt;
    });
    // Faces where the velocity is prescribed (walls, inflow): the pressure
    // condition there (Neumann) only keeps uf fixed; their gradient is not
    // the fluid's, so g comes from the interior face beside them.
    const std::array<bool, 6> prescribed = prescribed_faces(block);
    // The direction a compile-time constant: the face number n along it is
    // then i or a row constant, and the loop vectorises.
    auto along = [&]<int Dir>(std::integral_constant<int, Dir>) {
      const std::ptrdiff_t s = L.stride(Dir);
      const double* a = accel_[D(Dir)].block(blk);
      const double* open = open_[D(Dir)].block(blk);
      double* gb = g_[D(Dir)].block(blk);
      double* ub = u_[D(Dir)].block(blk);
      const bool shut_lo = prescribed[D(face_index(Dir, 0))];
      const bool shut_hi = prescribed[D(face_index(Dir, 1))];
      for_each_row(L, [&](std::ptrdiff_t row, int j, int k) {
      // g and u are written, neither read at another cell.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
        for (int i = 0; i < b; ++i) {
          const std::ptrdiff_t c = row + i;
          const int n = Dir == 0 ? i : (Dir == 1 ? j : k);
          const double grad_lo = (pb[c] - pb[c - s]) / h_dt;
          const double grad_hi = (pb[c + s] - pb[c]) / h_dt;
          // Average over the faces open to the flow (both, away from solids
          // and prescribed boundaries).
          const double open_c = open[c], open_next = open[c + s];  // loaded either way
          const double open_lo = (n == 0 && shut_lo) ? 0.0 : open_c;
          const double open_hi = (n == b - 1 && shut_hi) ? 0.0 : open_next;
          const double weight = open_lo + open_hi;
          const double gd =
              weight > 0.0 ? (open_lo * (a[c] - grad_lo) + open_hi * (a[c + s] - grad_hi)) / weight
                           : 0.0;
          gb[c] = gd;
          ub[c] += dt * gd;
        }
      });
    };
    along(std::integral_constant<int, 0>{});
    along(std::integral_constant<int, 1>{});
    along(std::integral_constant<int, 2>{});
  });
  clear_solid_cells(u_);
  time_ += dt;
  return report;
}

void NavierStokes::reconcile_shared_faces(FaceField& uf, std::span<const int> gained,
                                          BlockField& level_before) {
  // Fresh layers: send_faces relies on zeros outside the face layers.
  const int n = forest_.local_blocks();
  const int b = forest_.block_cells();
  std::array<BlockField, 6> values;
  for (auto& layer : values) layer = BlockField(n, b);
  send_faces(forest_, values, LevelJump::Same,
             [&](int blk, int d, std::ptrdiff_t f) { return uf[D(d)].block(blk)[f]; });
  // A same-level neighbour's ghost copy of its old level gives its gain.
  forest_.exchange(level_before, 1, true);
  const BlockLayout L = level_before.layout();
  forest_.for_each_block([&](int blk) {
    // A block's gain is one number: the neighbour's, per block face (read
    // only for faces with a neighbour of the same level).
    const int level = forest_.block(blk).level;
    std::array<double, 6> gain_beside{};
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t lower = L.index(0, 0, 0) - L.stride(d);  // ghost beyond face (d, 0)
      const std::ptrdiff_t upper = L.index(0, 0, 0) + b * L.stride(d);
      gain_beside[D(face_index(d, 0))] = level - level_before.block(blk)[lower];
      gain_beside[D(face_index(d, 1))] = level - level_before.block(blk)[upper];
    }
    const auto mine_gained = static_cast<double>(gained[D(blk)]);
    for_received_faces(forest_, values, blk, LevelJump::Same,
                       [&](int d, int side, std::ptrdiff_t f, double theirs) {
                         double& mine = uf[D(d)].block(blk)[f];
                         const double theirs_gained = gain_beside[D(face_index(d, side))];
                         if (theirs_gained < mine_gained) {
                           mine = theirs;
                         } else if (theirs_gained == mine_gained) {
                           mine = 0.5 * (mine + theirs);
                         }
                       });
  });
}

void NavierStokes::balance_refined_children(FaceField& uf, std::span<const int> gained) const {
  const int b = forest_.block_cells();
  const BlockLayout L = uf[0].layout();
  const std::array<std::ptrdiff_t, 3> s{L.stride(0), L.stride(1), L.stride(2)};
  // Child n = x + 2y + 4z of a group; its cell's offset from the group's first.
  std::array<std::ptrdiff_t, 8> offset{};
  for (int child = 0; child < 8; ++child) {
    offset[D(child)] = (child & 1) * s[0] + ((child >> 1) & 1) * s[1] + ((child >> 2) & 1) * s[2];
  }
  // (-1)^{popcount(mode & child)}: the eigenvectors of the cube's graph
  // Laplacian (8 children, 12 inner faces), eigenvalue 2 popcount(mode).
  const auto walsh = [](int mode, int child) {
    return (std::popcount(static_cast<unsigned>(mode & child)) & 1) != 0 ? -1.0 : 1.0;
  };
  forest_.for_each_block([&](int blk) {
    if (gained[D(blk)] <= 0) return;  // restriction keeps every cell divergence-free
    std::array<double*, 3> u{uf[0].block(blk), uf[1].block(blk), uf[2].block(blk)};
    std::array<const double*, 3> open{open_[0].block(blk), open_[1].block(blk),
                                      open_[2].block(blk)};
    for (int k = 0; k < b; k += 2)
      for (int j = 0; j < b; j += 2)
        for (int i = 0; i < b; i += 2) {
          const std::ptrdiff_t first = L.index(i, j, k);
          bool closed = false;
          std::array<double, 8> divergence{};
          double mean = 0.0;
          for (int child = 0; child < 8; ++child) {
            const std::ptrdiff_t c = first + offset[D(child)];
            for (int d = 0; d < 3; ++d) {
              divergence[D(child)] += u[D(d)][c + s[D(d)]] - u[D(d)][c];
              if (((child >> d) & 1) == 0) closed = closed || open[D(d)][c + s[D(d)]] == 0.0;
            }
            mean += divergence[D(child)] / 8.0;
          }
          if (closed) continue;
          // Solve (graph Laplacian) phi = -(divergence - its mean) mode by
          // mode; an inner face between children a (low) and a + 2^d then
          // changes by phi_a - phi_(a + 2^d), each child's divergence by
          // its row of the Laplacian. The mean (the parent's own divergence,
          // round-off after a projection) no inner face can change.
          std::array<double, 8> phi{};
          for (int mode = 1; mode < 8; ++mode) {
            double amplitude = 0.0;
            for (int child = 0; child < 8; ++child) {
              amplitude -= walsh(mode, child) * (divergence[D(child)] - mean);
            }
            amplitude /= 8.0 * 2.0 * std::popcount(static_cast<unsigned>(mode));
            for (int child = 0; child < 8; ++child) phi[D(child)] += walsh(mode, child) * amplitude;
          }
          for (int child = 0; child < 8; ++child)
            for (int d = 0; d < 3; ++d) {
              if (((child >> d) & 1) != 0) continue;
              u[D(d)][first + offset[D(child)] + s[D(d)]] +=
                  phi[D(child)] - phi[D(child + (1 << d))];
            }
        }
  });
}

RegridReport NavierStokes::regrid(Forest& forest, std::span<const AdaptFlag> flags,
                                  std::span<BlockField* const> scalars, int max_level) {
  if (&forest != &forest_) {
    throw std::invalid_argument("navier-stokes: regrid needs the forest the solver was built on");
  }
  if (flags.size() != static_cast<std::size_t>(forest.local_blocks())) {
    throw std::invalid_argument("navier-stokes: regrid needs one flag per local block");
  }
  if (has_solids_ && (max_level >= kForestMaxLevel || max_level < forest.max_level())) {
    throw std::invalid_argument(
        "navier-stokes: with solid cells, regrid needs max_level (below 18 and not below the "
        "forest's finest level): the blocks near solids are kept at that level");
  }
  RegridReport report;
  report.blocks_before = forest.global_blocks();
  // Each block's level rides along as a cell field (a constant is prolonged
  // and restricted exactly), so that afterwards every block, on whatever
  // rank, knows how many levels it gained (reconcile_shared_faces).
  BlockField level_before(forest.local_blocks(), forest.block_cells());
  forest.for_each_block([&](int blk) {
    const auto level = static_cast<double>(forest.block(blk).level);
    for_each_cell(forest.block_cells(),
                  [&](int i, int j, int k) { level_before(blk, i, j, k) = level; });
  });
  // The scratch fields are rebuilt from the state at every step.
  std::vector<BlockField*> cells{&u_[0], &u_[1], &u_[2], &g_[0],        &g_[1],
                                 &g_[2], &p_,    &mu_,   &predictor_p_, &level_before};
  for (auto& f : viscous_increment_) cells.push_back(&f);
  cells.insert(cells.end(), scalars.begin(), scalars.end());
  FaceField* faces[] = {&uf_, &accel_};
  std::vector<AdaptFlag> wanted(flags.begin(), flags.end());
  if (has_solids_) keep_solids_finest(wanted, max_level);
  report.changed = forest.adapt(wanted, cells, faces, max_level);
  // Blocks near solids that are not yet at max_level (a first regrid, or the
  // 2:1 balance) are refined on until every one is. An unchanged forest is
  // settled: its near blocks below max_level were all flagged Refine above.
  bool settled = !has_solids_ || !report.changed;
  for (int pass = 0; !settled && pass <= max_level; ++pass) {
    std::vector<AdaptFlag> more(static_cast<std::size_t>(forest.local_blocks()), AdaptFlag::Keep);
    settled = !keep_solids_finest(more, max_level);
    if (!settled) forest.adapt(more, cells, faces, max_level);
  }
  if (!settled) {
    throw std::logic_error("navier-stokes: regrid left blocks near solids below max_level");
  }
  report.blocks_after = forest.global_blocks();
  if (!report.changed) return report;

  allocate_work_fields();
  pressure_mg_->rebuild();
  viscous_mg_->rebuild();
  viscous_dt_ = -1.0;
  viscosity_changed_ = true;
  if (body_force_) set_body_force(body_force_);
  if (viscosity_function_) set_viscosity(viscosity_function_);
  if (has_solids_) {
    sample_solid();
    clear_solid_cells(u_);
    close_solid_faces(uf_);
  }
  // The carried uf keeps every old face's flux, but a block refined beside
  // finer ones gave its children the coarse face's value where the finer
  // neighbour has its own: between blocks of one level the neighbour's
  // values are taken; where the new children are the coarse side of a level
  // jump (the 2:1 balance refined them with their finer neighbour), their
  // copies become the mean of the fine faces across. Each old cell's total
  // flux is kept, only its split changes, and a local projection in each
  // group of 8 children gives every child its parent's divergence again.
  // The projection below then has nothing left to do, except where the grid
  // changed what it prescribes (solid faces sampled on new cells, inflow
  // faces: their fine means). Blocks gain two levels only in the settling
  // passes near solids, from the finest level, where no face is finer than
  // theirs (docs/theory/flow.md, "Adapting during a run").
  set_boundary_faces(uf_);
  // (A restricted face and the coarse copy it meets differ by round-off, the
  // mean of 4 taken two ways: reconcile_shared_faces evens those too.)
  std::vector<int> gained(static_cast<std::size_t>(forest.local_blocks()));
  forest.for_each_block([&](int blk) {
    gained[D(blk)] =
        forest.block(blk).level - static_cast<int>(std::lround(level_before(blk, 0, 0, 0)));
  });
  reconcile_shared_faces(uf_, gained, level_before);
  if (composite_) synchronise_coarse_faces(uf_);
  balance_refined_children(uf_, gained);
  // The potential in a scratch field, as set_velocity's (a new field would be fresh pages).
  BlockField& potential = scratch_[1];
  potential.fill(0.0);
  report.projection_cycles = project(potential).cycles;
  fill_velocity_ghosts(u_);
  return report;
}

double NavierStokes::max_divergence() const {
  const int b = forest_.block_cells();
  const BlockLayout L = p_.layout();
  double worst = 0.0;
  for (int blk = 0; blk < forest_.local_blocks(); ++blk) {
    const double h = forest_.block(blk).length / b;
    for_each_cell(b, [&](int i, int j, int k) {
      const std::ptrdiff_t c = L.index(i, j, k);
      double div = 0.0;
      for (int d = 0; d < 3; ++d)
        div += uf_[D(d)].block(blk)[c + L.stride(d)] - uf_[D(d)].block(blk)[c];
      worst = std::max(worst, std::abs(div) / h);
    });
  }
  return forest_.max(worst);
}

BlockField NavierStokes::vorticity_magnitude() {
  const int b = forest_.block_cells();
  fill_velocity_ghosts(u_, 1);
  BlockField out(forest_.local_blocks(), b);
  const BlockLayout L = out.layout();
  forest_.for_each_block([&](int blk) {
    const double h = forest_.block(blk).length / b;
    auto dd = [&](int comp, int d, std::ptrdiff_t c) {
      const double* u = u_[D(comp)].block(blk);
      return (u[c + L.stride(d)] - u[c - L.stride(d)]) / (2.0 * h);
    };
    for_each_cell(b, [&](int i, int j, int k) {
      const std::ptrdiff_t c = L.index(i, j, k);
      const double wx = dd(2, 1, c) - dd(1, 2, c);
      const double wy = dd(0, 2, c) - dd(2, 0, c);
      const double wz = dd(1, 0, c) - dd(0, 1, c);
      out.block(blk)[c] = std::sqrt(wx * wx + wy * wy + wz * wz);
    });
  });
  return out;
}

}  // namespace sanguis::flow
