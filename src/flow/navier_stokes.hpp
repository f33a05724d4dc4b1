#pragma once
// Incompressible Navier-Stokes equations, constant density, variable
// viscosity, body force (thesis eq. 4.1-4.2):
//
//     rho (du/dt + u.grad u) = -grad p + div(mu (grad u + grad u^T)) + f_b
//     div u = 0
//
// on a forest of blocks, following the solver the thesis used (Basilisk
// navier-stokes/centered.h, §4.3.1; Popinet 2003, 2009): a velocity u and the
// pressure p at cell centres, a face velocity uf that is exactly
// divergence-free (to the multigrid tolerance), body forces on faces.
// One step, dt:
//   1. prediction: uf at t + dt/2 from u by the Bell-Colella-Glaz upwind
//      scheme (Bell, Colella & Glaz 1989), MAC-projected with dt/2;
//   2. advection: u* = u - dt div(uf u_{n+1/2}) with the face values of u by
//      BCG (second order in space and time);
//   3. viscosity: (rho/dt - theta div(mu grad)) u** = rho/dt (u* + dt g) +
//      (1 - theta) div(mu grad u), then u** -= dt g (theta = 1 backward
//      Euler, 1/2 Crank-Nicolson), solved by multigrid;
//   4. acceleration: uf = face mean of u** (fourth order) + dt a (a = f_b / rho
//      on faces);
//   5. projection (Chorin 1968): div((dt/rho) grad p) = div uf,
//      uf -= (dt/rho) grad p, g = cell average of (a - grad p / rho),
//      u = u** + dt g.
// The term div(mu grad u^T) vanishes for uniform mu; for variable mu it is
// added explicitly (with u^n) to the right-hand side of the viscous step.
// Face viscosities are harmonic means of the two cells.
//
// Statically refined forests (issue #7, second milestone): blocks one level
// apart across faces. At a coarse-fine face the fine faces win: the coarse
// block's face value (face velocity, advective flux, projection gradient) is
// the mean of the 4 fine ones across it, so that the coarse cell's flux is
// the sum of the fine fluxes (conservation) and the projection, which solves
// the composite Poisson problem of Multigrid (flux matching), leaves every
// cell, coarse ones beside the interface included, divergence-free to the
// solver's residual. One dt for all levels (no subcycling), from the CFL
// condition on the finest cells. Solid masks on such forests are kept clear of
// level jumps: every block whose cells, or the 2 cells beyond its faces, edges
// and corners, hold a solid cell is at the finest level (regrid keeps it so), so
// a coarse-fine face never has a closed face or a wall closure within reach of
// its stencils. Variable viscosity works there too: the implicit part goes
// through the composite multigrid (flux matching with the fine faces' mu),
// the explicit parts (grad u^T, and the Crank-Nicolson half) are face fluxes
// matched like the advective ones.

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "core/error.hpp"
#include "flow/block_field.hpp"
#include "flow/boundary.hpp"
#include "flow/forest.hpp"
#include "flow/multigrid.hpp"

namespace sanguis::flow {

enum class FlowBoundaryKind : std::uint8_t {
  Periodic,  ///< the forest is periodic in this direction
  Wall,      ///< no-slip wall moving with `wall_velocity` (tangential)
  Inflow,    ///< prescribed velocity `inflow(x, t)`
  Outflow,   ///< zero normal gradient of velocity, pressure 0
};

using VelocityProfile = std::function<Vec3(const Vec3& x, double t)>;

struct FlowBoundary {
  FlowBoundaryKind kind = FlowBoundaryKind::Wall;  ///< condition type
  Vec3 wall_velocity{};                            ///< Wall: velocity of the wall (m/s)
  VelocityProfile inflow;                          ///< Inflow: velocity on the face (m/s)
};

struct Fluid {
  double density = 1.0;    ///< rho (kg/m^3)
  double viscosity = 1.0;  ///< mu (Pa s), the uniform value the viscosity field starts from
};

struct NavierStokesOptions {
  double cfl = 0.8;  ///< dt <= cfl h / max |uf| (BCG is stable up to 1)
  double dt_max = std::numeric_limits<double>::infinity();  ///< user maximum (s)
  double viscous_theta = 1.0;  ///< implicitness of the viscous step (1: Euler, 0.5: CN)
  /// Projection solves (Poisson). Over-relaxation 1.25 rather than the
  /// multigrid's general 1.15: on the pressure problems it reduces the residual
  /// more per V-cycle on uniform, masked and refined forests alike (tests of
  /// 2026-11-25: uniform periodic 64^3 14x -> 26x, masked walls 23x -> 104x,
  /// refined 12-16x -> 16-21x), and refined forests lose convergence only
  /// past 1.3 (docs/performance.md, "Over-relaxation of the pressure solves").
  MultigridOptions pressure{1e-6, 50, 2, 2, 1.25};
  MultigridOptions viscous{1e-6, 50, 2, 2, 1.15};  ///< viscous solves
  /// Both multigrids solve on the merged blocks of a uniform forest of
  /// blocks smaller than 16^3 (Multigrid's merge_blocks): about 1.5x faster
  /// steps of the 64^3 cavity with 8^3 blocks. false: on the flow's blocks
  /// (A/B runs; the answers differ within the solvers' tolerance).
  bool merge_solver_blocks = true;
  /// On refined forests, give the BCG face values of every block coarser than
  /// the finest the finest level's leading error (a second-difference term;
  /// navier_stokes.cpp, level_matched_term), so that it does not jump at
  /// coarse-fine faces: in the predictor, the momentum and passive tracers
  /// (advect_scalar) alike. Uniform forests and the finest blocks are unchanged
  /// to the bit. Off by default until the adaptive validations are rerun with
  /// it (docs/theory/flow.md, "Still open", the paragraph "Then the same idea
  /// without touching uniform grids": the refined 2D Taylor-Green error
  /// 1.395e-3 -> 9.29e-4, the adaptive vortex's far field 1.79x -> 1.29x the
  /// uniform run's).
  bool level_matched_advection = false;
};

/// What one step did.
struct StepReport {
  double dt = 0.0;
  int pressure_cycles = 0;          ///< V-cycles of the final projection
  int predictor_cycles = 0;         ///< V-cycles of the predictor projection
  int viscous_cycles = 0;           ///< V-cycles of the three viscous solves
  double pressure_reduction = 0.0;  ///< mean residual reduction per cycle (final projection)
};

/// What one regrid did.
struct RegridReport {
  bool changed = false;            ///< some block was refined or coarsened (any rank)
  std::int64_t blocks_before = 0;  ///< blocks over all ranks
  std::int64_t blocks_after = 0;
  int projection_cycles = 0;  ///< V-cycles of the projection of the carried uf
};

class NavierStokes {
 public:
  NavierStokes(const Forest& forest, const std::array<FlowBoundary, 6>& boundaries,
               const Fluid& fluid, const NavierStokesOptions& options = {});

  /// Sets u(x) at cell centres, projects it (uf exactly divergence-free),
  /// resets the pressure and the time.
  void set_velocity(const std::function<Vec3(const Vec3&)>& u, double time = 0.0);
  /// Body force density f_b(x) (N/m^3), sampled on faces (again after each regrid).
  void set_body_force(const std::function<Vec3(const Vec3&)>& f);
  /// Dynamic viscosity mu(x) (Pa s) per cell, sampled at cell centres. The
  /// function is kept and sampled again after each regrid (so that a jump
  /// stays sharp on the new cells): it must stay valid, be safe to call from
  /// several threads and not throw. An empty function forgets it and keeps
  /// the values (then they are carried by regrids like the velocity).
  void set_viscosity(const std::function<double(const Vec3&)>& mu);

  /// Solid cells (cell masks aligned with the grid): solid(x) at cell
  /// centres. Solid cells hold no flow; their faces with fluid cells are
  /// no-slip walls (linear closure) closed to the flow. Call before set_velocity.
  /// The mask is sampled again after each regrid, so solid(x) must stay
  /// valid, and it is called from several threads at once: it must be
  /// thread-safe and must not throw. Solids should be aligned with the
  /// forest's initial grid (ForestSpec level): the test that keeps blocks
  /// near solids at the finest level samples solid(x) at the cell centres of
  /// the block and of its 2-cell ghost band (at the initial grid's resolution
  /// in coarser blocks), so a solid face between finer cells' centres in the
  /// outer half of that band can be missed. On a forest with several levels
  /// the blocks near solids must already be at the finest level
  /// (std::invalid_argument otherwise; the solver is left unchanged).
  void set_solid(const std::function<bool(const Vec3&)>& solid);
  [[nodiscard]] const BlockField& solid() const { return solid_; }
  /// Force of the fluid on the solid cells (N): on every face between a fluid
  /// and a solid cell, the fluid cell's pressure along the normal and the
  /// tangential wall shear of the no-slip closure, mu u_t / (h/2) with the
  /// fluid cell's velocity at the end of the step.
  [[nodiscard]] Vec3 solid_force() const;

  /// Largest stable step: min(dt_max, cfl h / max|uf|).
  [[nodiscard]] double stable_dt() const;
  /// Advances by dt.
  StepReport step(double dt);

  /// Adapts the forest during a run (issue #7): `forest` is the one the
  /// solver was built on, passed again without const. Forest::adapt applies
  /// `flags` (one per local block; 2:1 balance, repartition) and carries the
  /// state: velocity, pressure, g, viscosity and the caller's `scalars`
  /// (tracers) by volume-average restriction and minmod-limited second-order
  /// prolongation (both keep every cell's total), the face velocity
  /// flux-keeping. The multigrid solvers are rebuilt, the body force is
  /// sampled on the new faces, and the carried face velocity is projected
  /// once more (refinement beside finer blocks leaves an O(h^2) divergence),
  /// so that uf is divergence-free to the projection tolerance, as after a
  /// step. With solid cells, blocks near them are refined to `max_level`
  /// and never coarsened (max_level must then be given), and the mask is
  /// sampled again. A viscosity function given to set_viscosity is sampled
  /// again too (values written through viscosity() are then overwritten:
  /// set_viscosity({}) forgets the function); otherwise mu is carried like
  /// the velocity.
  RegridReport regrid(Forest& forest, std::span<const AdaptFlag> flags,
                      std::span<BlockField* const> scalars = {}, int max_level = kForestMaxLevel);

  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] const Forest& forest() const { return forest_; }
  [[nodiscard]] VectorField& velocity() { return u_; }
  [[nodiscard]] const VectorField& velocity() const { return u_; }
  [[nodiscard]] const FaceField& face_velocity() const { return uf_; }
  [[nodiscard]] FaceField& face_velocity() { return uf_; }
  [[nodiscard]] BlockField& pressure() { return p_; }
  [[nodiscard]] const BlockField& pressure() const { return p_; }
  /// The pressure correction the predictor projection found at the last
  /// step (Pa): the warm start of the next one, so part of the state.
  [[nodiscard]] BlockField& predictor_pressure() { return predictor_p_; }
  [[nodiscard]] const BlockField& predictor_pressure() const { return predictor_p_; }
  /// The last step's viscous increment per component, u** - (u* + dt g)
  /// (m/s): the warm start of the next viscous solves, so part of the state.
  [[nodiscard]] VectorField& viscous_increment() { return viscous_increment_; }
  [[nodiscard]] const VectorField& viscous_increment() const { return viscous_increment_; }
  [[nodiscard]] const BlockField& viscosity() const { return mu_; }
  /// Writable viscosity field (e.g. set from a phase indicator): taking it
  /// marks the viscous coefficients for rebuilding at the next step, so take
  /// it again after each write, on every rank (the rebuild is collective).
  [[nodiscard]] BlockField& viscosity() {
    viscosity_changed_ = true;
    return mu_;
  }
  [[nodiscard]] const VectorField& pressure_gradient() const { return g_; }
  [[nodiscard]] VectorField& pressure_gradient() { return g_; }
  [[nodiscard]] const Fluid& fluid() const { return fluid_; }
  [[nodiscard]] const std::array<FlowBoundary, 6>& boundaries() const { return boundaries_; }
  void set_time(double t) { time_ = t; }

  /// Largest |div uf| over all cells (1/s): zero to the projection tolerance.
  [[nodiscard]] double max_divergence() const;
  /// The viscous force density div(mu (grad u + grad u^T)) (N/m^3) of the
  /// current velocity at cell centres (grad u^T included even for uniform
  /// mu), from the face fluxes the step's explicit part uses: on any forest,
  /// without solid cells (whose no-slip closure is a cell term), its volume
  /// integral is the flux through the domain boundary (zero when periodic)
  /// to round-off.
  [[nodiscard]] VectorField viscous_force_density();
  /// |curl u| at cell centres (1/s), central differences.
  [[nodiscard]] BlockField vorticity_magnitude();
  /// Advects a passive scalar by dt with the current face velocity uf (the
  /// BCG fluxes of step 2, no source, zero-gradient ghosts at the domain
  /// boundary): conservative on every forest, coarse-fine faces included.
  void advect_scalar(BlockField& c, double dt);
  /// Fills the ghost cells of the velocity (width 2) with the boundary conditions.
  void fill_velocity_ghosts(VectorField& u, int width = kGhost);
  /// Cells per edge of the blocks the multigrids solve on: the forest's, or
  /// twice that where they merge its families of 8 (uniform forests of
  /// blocks below 16^3, merge_solver_blocks).
  [[nodiscard]] int solver_block_cells() const { return pressure_mg_->solver_block_cells(); }
  /// The last multigrid report of the final projection.
  [[nodiscard]] const MultigridReport& last_pressure_report() const { return pressure_report_; }

 private:
  /// kernel(blk) for every block, each block's velocity ghosts (width; and the ghosts of
  /// `neumann`, width 1, Neumann at the domain's boundary, when given) filled first: block
  /// by block inside the loop on a uniform one-process forest (Forest::uniform_local), else
  /// by fill_velocity_ghosts and fill_neumann_ghosts before it. The kernel must not write u
  /// or `neumann`.
  template <class Kernel>
  void for_each_block_with_velocity_ghosts(VectorField& u, int width, VectorField* neumann,
                                           Kernel&& kernel);
  /// The face velocity at t + dt/2 (BCG) from u and g; fills their ghosts first.
  void predict_face_velocity(double dt);
  void advect(double dt);
  /// out = f - dt div(uf f_{n+1/2}), BCG face values with the cell source
  /// `source` (nullptr: none) and the boundary kinds of f (Dirichlet faces take
  /// the boundary value); f's ghosts must be filled.
  void advect_field(const BlockField& f, const BlockField* source,
                    const std::array<BcKind, 6>& kinds, BlockField& out, double dt);
  /// Composite grids: the coarse block's faces at coarse-fine faces get the
  /// mean of the 4 fine faces across (the fine faces win).
  void synchronise_coarse_faces(FaceField& uf);
  void viscous_step(double dt, StepReport& report);
  /// uf = the face mean of u (face_mean, fourth order; the plain average
  /// near walls, inflows and solids) + dt a, before the projection.
  void face_average_plus_acceleration(double dt);
  /// max |uf| / h over the faces of all ranks (1/s).
  [[nodiscard]] double max_face_rate() const;
  MultigridReport project(BlockField& phi);
  void set_boundary_faces(FaceField& uf) const;
  /// Which of the block's 6 faces lie on a domain face whose velocity is
  /// prescribed (a wall or an inflow).
  [[nodiscard]] std::array<bool, 6> prescribed_faces(const Block& block) const;
  /// The mean over an inflow face (component d, centre x, beside cell
  /// `cell` of a block with `prescribed` faces) of the profile, as
  /// face_mean takes it.
  [[nodiscard]] double inflow_face_mean(const FlowBoundary& inflow,
                                        const std::array<bool, 6>& prescribed, Vec3 x,
                                        const std::array<int, 3>& cell, int d, double h) const;
  void fill_face_ghosts(FaceField& uf);
  void fill_scalar_neumann(BlockField& f, int width);
  /// fill_scalar_neumann() for the three components of v, one exchange.
  void fill_neumann_ghosts(VectorField& v, int width);
  void update_viscous_coefficients(double dt);
  void close_solid_faces(FaceField& uf) const;
  /// out += factor div(mu (laplacian_weight grad u + [transpose] grad u^T))
  /// from face fluxes (matched at coarse-fine faces), plus the no-slip
  /// closure of solid faces in the first part (a cell term, not a flux);
  /// u's ghosts and mu's (width 1) must be filled.
  void add_viscous_fluxes(double laplacian_weight, bool transpose, double factor, VectorField& out);
  /// mu's ghost layer (width 1), clamped to the field's range on composite
  /// grids; the range and variable_viscosity_ first if mu changed.
  void fill_viscosity_ghosts();
  /// Calls update(blk, fluxes) for every block with the fluxes of all its
  /// faces along the 3 directions: block_fluxes(blk, d, out) writes the faces
  /// 0..b of a block; on composite grids each shared face is evaluated once,
  /// upper_flux(blk, d, f) gives a face of layer b where the upper neighbour
  /// is the boundary or coarser, and coarse faces at coarse-fine faces take
  /// the mean of the 4 fine ones (conservation to round-off).
  template <typename BlockFluxes, typename UpperFlux, typename Update>
  void update_from_face_fluxes(BlockFluxes&& block_fluxes, UpperFlux&& upper_flux, Update&& update);
  void clear_solid_cells(VectorField& u) const;
  /// solid_, open_ and the pressure coefficients from solid_function_.
  void sample_solid();
  /// Whether a solid cell lies in the cube (lower, length) of a block at
  /// `level` or within kGhost of its cells beyond it, sampled at its cell
  /// centres (at the initial grid's resolution where that is finer).
  [[nodiscard]] bool near_solid(const Vec3& lower, double length, int level) const;
  /// Overrides `flags` so that blocks near solids go to max_level and no
  /// family coarsens into a block near solids; true if any rank refines.
  bool keep_solids_finest(std::vector<AdaptFlag>& flags, int max_level) const;
  /// Blocks near solids (all ranks) below `level`.
  [[nodiscard]] std::int64_t blocks_near_solids_below(int level) const;
  /// Scratch, masks and interface layers sized to the current block list.
  void allocate_work_fields();
  /// After a regrid, both copies of a face shared by two blocks of one level
  /// agree again. They differ where a block was refined beside finer ones:
  /// its children took the coarse face's value, the neighbour has the fine
  /// values. The copy of the block that gained fewer levels in the regrid
  /// (`gained`, per local block) holds the finer data and wins; equal gains
  /// came from the same data and take the mean (round-off apart, the same).
  /// `level_before`: each block's level before the regrid as a constant cell
  /// field; its face ghosts are filled here and give the neighbours' gains.
  void reconcile_shared_faces(FaceField& uf, std::span<const int> gained, BlockField& level_before);
  /// Then, in every refined block, each group of the 8 children of one old
  /// cell gets back its parent's divergence in every child (the residual the
  /// last projection left) from a local projection on its 12 inner faces:
  /// the fluxes through the group's outer faces still sum to the parent's,
  /// only their split changed. uf is then as divergence-free as before the
  /// regrid, without a global solve. Groups with a closed inner face
  /// (solids) and blocks that gained two levels are left to the projection
  /// that follows.
  void balance_refined_children(FaceField& uf, std::span<const int> gained) const;

  const Forest& forest_;
  std::array<FlowBoundary, 6> boundaries_;
  Fluid fluid_;
  NavierStokesOptions options_;
  double time_ = 0.0;
  double bc_time_ = 0.0;  ///< time at which inflow profiles are evaluated

  VectorField u_;           ///< cell-centred velocity (m/s)
  VectorField g_;           ///< cell-centred a - grad p / rho (m/s^2)
  BlockField p_;            ///< cell-centred pressure (Pa)
  BlockField predictor_p_;  ///< pressure correction of the predictor projection (Pa), warm start
  FaceField uf_;            ///< face velocity, exactly divergence-free after a step (m/s)
  FaceField accel_;         ///< body force / rho on faces (m/s^2)
  VectorField viscous_increment_;        ///< last viscous increment per component (m/s), warm start
  BlockField mu_;                        ///< dynamic viscosity per cell (Pa s)
  VectorField scratch_;                  ///< u* and other temporaries
  std::vector<double> block_face_rate_;  ///< project(): per local block max |uf| / h

  std::array<ScalarBoundary, 3> velocity_bc_;  ///< per velocity component
  ScalarBoundary pressure_bc_;
  std::optional<Multigrid> pressure_mg_;  ///< rebuilt when the forest adapts
  std::optional<Multigrid> viscous_mg_;
  std::function<Vec3(const Vec3&)> body_force_;  ///< as given, to sample again after a regrid
  std::function<double(const Vec3&)> viscosity_function_;  ///< likewise, for set_viscosity
  double viscous_dt_ = -1.0;  ///< dt the viscous coefficients were built for
  bool viscosity_changed_ = true;
  bool has_solids_ = false;
  std::function<bool(const Vec3&)> solid_function_;  ///< as given, to sample again after a regrid
  bool variable_viscosity_ = false;          ///< mu not uniform: the grad u^T stress is added
  std::array<double, 2> viscosity_range_{};  ///< min and max of mu over all ranks
  BlockField solid_;                         ///< 1 in solid cells, 0 in fluid cells
  FaceField
      open_;  ///< 1 on faces between two fluid cells (or fluid and the domain boundary), else 0
  MultigridReport pressure_report_;
  bool composite_ = false;  ///< blocks at more than one level
  /// Composite grids: per block face, the fine faces' values travelling to
  /// the coarse block (face layer of the fine block, see send_faces).
  std::array<BlockField, 6> interface_;
  FaceField face_flux_;  ///< composite grids: advective or viscous fluxes of all faces
};

}  // namespace sanguis::flow
