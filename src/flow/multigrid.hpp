#pragma once
// Geometric multigrid for the variable-coefficient Poisson-Helmholtz problem
//
//     alpha x - div(beta grad x) = rhs                                   (1)
//
// on a forest of blocks, cell-centred, second order (7-point stencil, beta on
// faces). It serves the pressure projection (alpha = 0, beta = dt/rho) and the
// implicit viscous step (alpha = 1, beta = dt mu/rho) of the flow solver
// (thesis §4.3.1: "the viscous term is treated implicitly using a multigrid
// Poisson solver"; Popinet 2003, 2015).
//
// Levels: inside every block the cells halve B -> B/2 -> ... -> 2 (red-black
// Gauss-Seidel smoothing, residual by 8-cell averaging, trilinear
// prolongation of the correction); the level with one cell per block is the
// forest's own grid of blocks (the merged ones, below, when merged), gathered
// on every rank and solved there by conjugate gradients (identical on every
// rank). Boundary values are applied on the finest level only; corrections
// carry homogeneous conditions.
// Cells closed on all faces with alpha = 0 (solid cells of a mask) are
// inactive: no row of the operator reads them and the smoother leaves them,
// and the prolongation interpolates from active coarse cells only
// (renormalised weights), so that masked walls act as Neumann boundaries on
// every level. Their values carry whatever corrections the prolongation adds
// there, which depend on the hierarchy (merged solver blocks or not): no part
// of the solution.
//
// Uniform forests of blocks smaller than 16^3 (the default 8^3) are solved on
// a second forest of their families of 8 merged (merged_blocks.hpp), the
// caller's fields copied in and out: per block the V-cycle pays for ghost
// fills, loop heads and in-block levels of 4^3 and 2^3 cells, so on the 64^3
// cavity it runs 2-3x faster on 16^3 blocks (docs/performance.md, "Solver
// blocks").
//
// Composite grids (blocks at several levels, issue #7): by default the level
// below the finest is the forest with its finest level coarsened (its families
// merged into their parents, the same cells per block: coarsened_blocks.hpp),
// solved by a Multigrid of its own, and so on down to a uniform forest; each
// forest relaxes its finest level only. This converges per cycle about as the
// uniform grids do (docs/theory/flow.md, "Level by level"). With
// level_by_level false (comparisons), every in-block level
// is itself a composite grid with the same 2:1 structure, and the V-cycle is
// unchanged: Forest::exchange fills fine ghosts from coarser blocks by
// quadratic interpolation and coarse ghosts from finer blocks by averaging.
// The operator is made conservative (flux matching): at a coarse-fine face
// the coarse cell's flux is the mean of the 4 fine fluxes computed on the
// fine side. match_fluxes() writes it into the coarse ghost (the value that
// gives that flux through the coarse stencil), so the residual needs no
// special case, and the smoother holds the matched flux fixed while it
// relaxes the coarse cell (lagged, like the fine ghosts interpolated from the
// coarse cells). On one process the coarse block reads the fine fluxes in
// place; across ranks they travel through an exchange (the same bits). The bottom level (one cell
// per block) is the graph of leaves, gathered on every rank and solved by CG with a two-point flux
// between blocks of different size (distance 1.5 h_fine). A forest that adapts needs a
// rebuild() (or a new Multigrid).

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "flow/block_field.hpp"
#include "flow/boundary.hpp"
#include "flow/coarsened_blocks.hpp"
#include "flow/forest.hpp"
#include "flow/merged_blocks.hpp"

namespace sanguis::flow {

/// When the smoother and the residual prefetch the next block's cells while
/// they work on one (docs/performance.md, "Prefetching the next block in the
/// smoother"): only when x and the right-hand side outgrow half the
/// last-level cache (in cache the prefetches only cost), always, or never.
/// A hint to the memory, so every choice gives the same bits.
///
/// The cache size comes from sysconf, which a virtual machine may report as
/// its host's whole cache (508 MiB on a 2-core AMD EPYC VM whose smoother
/// leaves the cache between 20 and 48 MB of fields). Where the reported
/// cache exceeds kUsualCoreCache and the fields lie between half of each,
/// OutOfCache times the level's first smoother calls both ways and keeps the
/// faster (PrefetchTrial; docs/performance.md, "The cache a VM reports").
enum class NextBlockPrefetch { OutOfCache, Always, Never };

/// The last-level cache one core of a common server processor reaches (a
/// CCD's L3 on AMD EPYC); below half of it the fields stay in cache.
inline constexpr double kUsualCoreCache = 32.0 * 1024 * 1024;

/// One level's choice between prefetching and not, where it is timed: the
/// first kTrialCalls smoother calls alternate (in Thue-Morse order, so that
/// each way gets as many pre- as post-smoothing calls of a V-cycle), then the
/// way with the shorter best call is kept. Fields whose size moves by more
/// than 2x (a regrid) start a new trial.
class PrefetchTrial {
 public:
  static constexpr int kTrialCalls = 16;
  /// Whether the next call prefetches (the trial's turn, or the decision).
  [[nodiscard]] bool next_choice(double field_bytes);
  /// Records a call's time (ignored once decided).
  void record(bool prefetching, double seconds);
  /// The decision; nullopt while the trial runs.
  [[nodiscard]] std::optional<bool> decision() const { return decided_; }

 private:
  double bytes_ = 0.0;
  int calls_ = 0;
  std::array<double, 2> best_{std::numeric_limits<double>::infinity(),
                              std::numeric_limits<double>::infinity()};
  std::optional<bool> decided_;
};

struct MultigridOptions {
  double tolerance = 1e-8;  ///< stop when |r|_2 <= tolerance |rhs|_2 (RMS norms)
  int max_cycles = 50;      ///< V-cycles at most
  int pre_sweeps = 2;       ///< red-black Gauss-Seidel sweeps before restriction
  int post_sweeps = 2;      ///< and after prolongation
  /// Over-relaxation of the red-black Gauss-Seidel sweeps (1.15: about 15x
  /// residual reduction per V(2,2) cycle on the 3D Poisson problem, against 9x at 1).
  double relaxation = 1.15;
  /// The relaxation of the cells beside a face with finer blocks across (at most
  /// `relaxation`). Their rows hold the matched fine fluxes, whose fine ghosts
  /// are interpolated from these very cells and lag a half-sweep behind, a
  /// Jacobi coupling that over-relaxation amplifies: at the pressure solves'
  /// 1.25, plain Gauss-Seidel there (1.0) takes the composite V-cycle on
  /// scattered refinement from 0.72-0.77 to 0.85-0.91 of the uniform rate; at
  /// 1.15 the rates move by at most 1.3 % (docs/performance.md, "Plain
  /// Gauss-Seidel beside finer blocks").
  double beside_finer_relaxation = 1.0;
  /// Also stop when |r|_2 <= absolute_tolerance (a floor above round-off for
  /// right-hand sides that are round-off themselves).
  double absolute_tolerance = 0.0;
  /// Blocks whose alpha (>= 0) and beta (> 0) are each one value (no solid
  /// cell, constant viscosity) relax and form residuals reading x and rhs only: the same operations
  /// in the same order, so the same bits (the build keeps FMA contraction off), Dirichlet closures
  /// and matched coarse-fine faces included; the residual needs no special case. false: always the
  /// general kernels (for tests and comparisons).
  bool constant_coefficient_kernels = true;
  /// The smoother and the V-cycle's residual read the cells of same-level
  /// blocks of this process in place instead of copying them into x's ghost
  /// layer first: the same values, so the same bits, without the copies.
  /// false: copy (for tests and comparisons).
  bool read_neighbours_in_place = true;
  /// Prefetching of the next block's cells (for tests and comparisons).
  NextBlockPrefetch prefetch = NextBlockPrefetch::OutOfCache;
  /// Fill x's ghosts (neighbours and bc) before returning. false where the
  /// caller refills them anyway (the viscous solves: the velocity's ghosts
  /// are filled again before anything reads them), saving a full exchange;
  /// x's ghosts are then stale (with read_neighbours_in_place the kernels
  /// read same-level neighbours in place and leave those ghosts as they were;
  /// on merged solver blocks none of x's ghosts is written, boundary ones included).
  bool fill_ghosts_on_return = true;
};

struct MultigridReport {
  int cycles = 0;                 ///< V-cycles done
  bool converged = false;         ///< tolerance reached
  double rhs_norm = 0.0;          ///< RMS of the right-hand side
  std::vector<double> residuals;  ///< RMS residual before the first and after each cycle
  /// Geometric mean of the residual reduction per cycle (>1: it shrinks).
  [[nodiscard]] double mean_reduction() const;
};

class Multigrid {
 public:
  /// kinds: the boundary condition kind on each domain face (periodic
  /// directions must say Periodic). merge_blocks: on a uniform forest of
  /// blocks smaller than 16^3, solve on the forest of its families of 8
  /// merged (merged_blocks.hpp: the same cells, half the blocks per
  /// direction; the caller's fields copied in and out), where a V-cycle of
  /// the 64^3 cavity costs about half what it costs on 8^3 blocks. false: the
  /// caller's blocks (for comparisons).
  /// level_by_level: on a composite forest, the level below the finest is the forest with
  /// its finest level coarsened (coarsened_blocks.hpp), and so on down to a uniform forest,
  /// whose blocks then halve their cells; false: every block halves its own cells from the
  /// finest level on (the block-by-block hierarchy, for comparisons).
  /// gathered_blocks_limit: a uniform forest whose blocks outnumber it (and that is not at
  /// the trees' level) coarsens level by level as well, down to where they do not: the
  /// bottom of the in-block levels, one cell per block, is gathered on every rank and
  /// solved there, which must stay small however many ranks share the grid.
  Multigrid(const Forest& forest, const std::array<BcKind, 6>& kinds, bool merge_blocks = true,
            bool level_by_level = true, std::int64_t gathered_blocks_limit = kGatheredBlocksLimit);
  /// The default gathered_blocks_limit: 4096 unknowns in the bottom solve (a 16^3 grid of
  /// blocks, 512^3 cells of 32^3 blocks).
  static constexpr std::int64_t kGatheredBlocksLimit = 4096;
  /// Forests below this one in the level-by-level hierarchy (0: none).
  [[nodiscard]] int coarsened_forests() const {
    if (merged_) return merged_->solver->coarsened_forests();
    return coarsened_ ? 1 + coarsened_->solver->coarsened_forests() : 0;
  }

  /// After the forest has changed (Forest::adapt): the levels for its new
  /// blocks, in the storage of the old ones where it is large enough, and
  /// the coefficients reset (alpha 0, beta 1), as a new Multigrid would have.
  /// A forest that merges (merge_blocks) gets a new merged forest and solver
  /// instead, and the levels of the caller's blocks are dropped.
  void rebuild();

  /// Coefficients of (1): alpha per cell (nullptr: 0) and beta per face
  /// (nullptr: 1), on the finest layout; beta must be valid on faces 0..b of
  /// every block (slot b of the ghost layer included). Builds the coarse levels.
  void set_coefficients(const BlockField* alpha, const FaceField* beta);

  /// Solves (1) for x (initial guess in x) with the boundary values `bc`
  /// (its kinds must match the constructor's).
  MultigridReport solve(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc,
                        const MultigridOptions& options = {});

  /// `sweeps` sweeps of the V-cycles' smoother (red-black Gauss-Seidel with
  /// the options' relaxation and kernels) on the finest level, ghosts filled
  /// as in a V-cycle: the smoother alone, for benchmarks and tests. On merged
  /// solver blocks the sweeps run there, with the copies in and out, and x's
  /// ghosts are left as they were.
  void relax(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc, int sweeps,
             const MultigridOptions& options = {});

  /// r = rhs - A x on the finest level (fills x's ghosts with bc).
  void residual(BlockField& x, const BlockField& rhs, const ScalarBoundary& bc, BlockField& r);

  /// Whether every block of `level` (0: finest; level by level, the levels below are the
  /// coarsened forest's), on every rank, runs the constant-coefficient kernels when
  /// MultigridOptions::constant_coefficient_kernels is on. On merged solver blocks: the merged
  /// blocks and their levels (level 0 has the same cells; level l has 2b >> l cells per merged
  /// block).
  [[nodiscard]] bool constant_coefficients(int level) const {
    if (merged_) return merged_->solver->constant_coefficients(level);
    if (coarsened_ && level > 0) return coarsened_->solver->constant_coefficients(level - 1);
    return levels_[static_cast<std::size_t>(level)].constant_coefficients;
  }
  /// How many of this rank's blocks of `level` run them (merged blocks when merged).
  [[nodiscard]] int constant_blocks(int level) const;

  /// True when the operator has the constants as null space (alpha = 0, no
  /// Dirichlet face): the solution is returned with zero mean.
  [[nodiscard]] bool singular() const { return merged_ ? merged_->solver->singular() : singular_; }

  /// Whether the solves run on the merged blocks (merge_blocks, a uniform
  /// forest of blocks smaller than 16^3 with at least 2 merged blocks per
  /// direction).
  [[nodiscard]] bool merged() const { return merged_ != nullptr; }
  /// Whether the V-cycle takes its coarse correction on the forest with the finest level
  /// coarsened (a composite forest with level_by_level).
  [[nodiscard]] bool level_by_level() const { return coarsened_ != nullptr; }
  /// Cells per edge of the blocks the solves run on (the merged ones when merged).
  [[nodiscard]] int solver_block_cells() const {
    return merged_ ? merged_->forest->block_cells() : forest_.block_cells();
  }
  /// Whether the last smoother call on the finest level prefetched the next
  /// block: "on" or "off" by the rule of NextBlockPrefetch, "timed on" or
  /// "timed off" where PrefetchTrial decided, "timing" while it runs, "" before
  /// any call (the merged blocks' solver when merged).
  [[nodiscard]] std::string finest_prefetch() const {
    return merged_ ? merged_->solver->finest_prefetch() : finest_prefetch_;
  }

 private:
  /// The sweeps, relaxation and kernels of `options`, for what follows.
  void take_options(const MultigridOptions& options);
  struct Level {
    int cells = 0;  ///< cells per block edge at this level
    BlockField x, rhs, alpha;
    FaceField beta;
    BlockField active;  ///< 1 where the cell takes part (some open face or alpha > 0), else 0
    /// Composite grids on several ranks: fine-side fluxes by face.
    std::array<BlockField, 6> face_flux;
    /// Per local block: 1 where alpha (>= 0) and beta (> 0) are each one value
    /// on the block's cells and faces 0..b and every cell is active; the values.
    std::vector<unsigned char> block_constant;
    std::vector<unsigned char> block_all_active;  ///< per local block: active is 1 in every cell
    /// Per local block: active is exactly 1 in every cell and in the ghost
    /// ring around them (what the trilinear prolongation from this level reads).
    std::vector<unsigned char> block_ring_active;
    std::vector<double> block_alpha, block_beta;
    /// Every block of every rank constant (then every cell and ghost is active).
    bool constant_coefficients = false;
  };
  /// Ghosts from the neighbours (Forest::exchange) and the boundary; on
  /// composite grids, coarse ghosts at coarse-fine faces then carry the
  /// matched fluxes (unless `match` is false: plain restricted values).
  void fill_ghosts(int level, BlockField& x, const ScalarBoundary* bc, bool faces_only = false,
                   bool match = true);
  /// The part of fill_ghosts(.., faces_only) that fill_block_ghosts() leaves:
  /// face ghosts towards other levels and ranks, then the matched fluxes.
  void fill_ghosts_between_blocks_apart(int level, BlockField& x);
  /// The rest of fill_ghosts(.., faces_only) for block `blk` alone: its face
  /// ghosts towards same-level blocks of this rank (`colour` as in
  /// Forest::copy_face_ghosts) and its boundary ghosts; with `in_place` (for
  /// kernels that read them in place, same_level_neighbours) neither the
  /// same-level faces nor the Neumann boundary faces.
  void fill_block_ghosts(int blk, BlockField& x, const ScalarBoundary* bc, int colour,
                         bool in_place = false) const;
  /// `sweeps` red-black sweeps over every block.
  void smooth(int level, BlockField& x, const BlockField& rhs, const ScalarBoundary* bc,
              int sweeps);
  /// One half-sweep (the cells of `colour`) of block `blk`, ghosts filled;
  /// with `in_place` the block reads the cells of its same-level neighbours
  /// of this rank, and its own cells beyond Neumann boundary faces, in place
  /// (those ghosts not filled).
  /// `next_blk` (or -1): the block relaxed after this one, whose cells are
  /// prefetched meanwhile (constant-coefficient blocks).
  void relax_block(int level, int blk, BlockField& x, const BlockField& rhs,
                   const ScalarBoundary* bc, int colour, bool in_place = false,
                   int next_blk = -1) const;
  /// r = rhs - A x on `level`, and each block's sum of r^2 into
  /// block_squares_ (one pass: summed as r is written; root_mean_square()),
  /// unless !squares_wanted (the V-cycle's residual, only restricted): then
  /// the constant-coefficient blocks' sums are not formed. r is stored in
  /// `r` when given, and its restriction to the next level (the mean of the
  /// 8 children) in `restricted` when given; each block's r is formed in a
  /// scratch block in cache otherwise (a pass over memory less). Unless
  /// ghosts_wanted, the kernels read same-level neighbours of this rank
  /// (read_neighbours_in_place) in place, and x's ghosts towards them are
  /// left as they were.
  void compute_residual(int level, BlockField& x, const BlockField& rhs, const ScalarBoundary* bc,
                        BlockField* r, bool squares_wanted = true, bool ghosts_wanted = false,
                        BlockField* restricted = nullptr);
  void vcycle(int level, BlockField& x, const BlockField& rhs, const ScalarBoundary* bc);
  /// The V-cycle of the level-by-level hierarchy on the finest level: relaxation, the
  /// residual restricted to the coarsened forest, one V-cycle there, its correction
  /// prolonged back, relaxation.
  void vcycle_level_by_level(BlockField& x, const BlockField& rhs, const ScalarBoundary* bc);
  /// x = one V-cycle from zero for rhs with homogeneous boundary values (the coarse
  /// correction of the level above), x's ghosts then filled with values.
  void correction(BlockField& x, const BlockField& rhs);
  void coarse_solve();
  void build_coarse_operator();
  void build_composite_operator();  ///< the bottom level of a non-uniform forest
  void composite_solve();
  /// Coarse ghosts at coarse-fine faces such that the coarse flux equals the
  /// mean of the fine fluxes across that face.
  void match_fluxes(int level, BlockField& x);
  /// match_fluxes() on one process: the fine fluxes read in place.
  void match_fluxes_local(int level, BlockField& x);
  double rms(const BlockField& f);
  /// sqrt(sum of block_squares_ / cells), all ranks; b: cells per block edge.
  double root_mean_square(int b) const;
  double mean(const BlockField& f) const;  ///< over the active cells of the finest level
  /// f -= by in the active cells of the finest level (the mean removal).
  void shift_interior(BlockField& f, double by) const;
  void compute_activity();
  /// active = 1 in the cells with an open face or alpha > 0, else 0 (not the ghosts).
  static void cell_activity(const Forest& forest, const BlockField& alpha, const FaceField& beta,
                            BlockField& active);
  void detect_constant_coefficients();

  /// The caller's fields into the merged solver's (cells; x unless null).
  void to_merged(const BlockField* x, const BlockField& rhs);
  /// The merged solver's x into the caller's, with fill_caller_ghosts after it.
  void from_merged(BlockField& x, const ScalarBoundary& bc, bool fill_ghosts) const;
  /// x's ghosts filled as fill_ghosts(0, x, &bc, false, false) fills them on
  /// a uniform forest (what solve() returns and residual() leaves).
  void fill_caller_ghosts(BlockField& x, const ScalarBoundary& bc) const;

  const Forest& forest_;
  std::array<BcKind, 6> kinds_;
  bool merge_blocks_ = true;
  /// The solver on the merged blocks, when it runs there: the forest, the
  /// copies, a Multigrid on it (not merging again) and its fields.
  struct Merged {
    std::unique_ptr<Forest> forest;
    std::unique_ptr<MergedBlocks> copies;
    std::unique_ptr<Multigrid> solver;
    BlockField x, rhs, r, alpha;
    FaceField beta;
  };
  std::unique_ptr<Merged> merged_;
  /// The level-by-level hierarchy's next forest (its finest level coarsened) and solver.
  struct Coarsened {
    std::unique_ptr<Forest> forest;
    std::unique_ptr<CoarsenedBlocks> transfers;
    std::unique_ptr<Multigrid> solver;
    BlockField x, rhs, alpha, active;  ///< on the coarsened forest
    FaceField beta;
    BlockField residual;  ///< on this forest
    bool all_active = true;
  };
  std::unique_ptr<Coarsened> coarsened_;
  bool level_by_level_ = true;
  std::int64_t gathered_blocks_limit_ = kGatheredBlocksLimit;
  ScalarBoundary homogeneous_;  ///< kinds_, zero values
  bool has_alpha_ = false;
  bool singular_ = false;
  std::vector<Level> levels_;  ///< 0 finest (b = B), last one cell per block
  bool composite_ = false;     ///< blocks at more than one level

  /// The bottom level of a composite grid: one cell per leaf in global p8est
  /// order, the volume-weighted (symmetric) operator in compressed rows.
  struct CompositeOperator {
    std::vector<double> volume, active, diagonal;
    std::vector<std::int64_t> row_start, column;
    std::vector<double> value;  ///< off-diagonal entries
  } composite_op_;

  // The grid of blocks, one cell each, gathered on every rank.
  std::array<std::int64_t, 3> coarse_n_{};
  std::vector<double> coarse_alpha_;
  std::vector<double> coarse_active_;
  std::array<std::vector<double>, 3> coarse_beta_;  ///< (n_d + 1) faces along d
  double coarse_h_ = 1.0;
  BlockField shifted_rhs_;             ///< zero-mean copy of the rhs of singular problems
  std::vector<double> block_squares_;  ///< per local block: sum of squares (rms, residuals)
  int pre_sweeps_ = 2;
  int post_sweeps_ = 2;
  double omega_ = 1.0;
  double beside_finer_omega_ = 1.0;  ///< min(omega_, MultigridOptions::beside_finer_relaxation)
  bool constant_kernels_ = true;  ///< MultigridOptions::constant_coefficient_kernels of the solve
  bool in_place_ = true;          ///< MultigridOptions::read_neighbours_in_place of the solve
  NextBlockPrefetch prefetch_ = NextBlockPrefetch::OutOfCache;  ///< MultigridOptions::prefetch
  std::vector<PrefetchTrial> prefetch_trials_;  ///< per level, where OutOfCache times it
  std::string finest_prefetch_;                 ///< what finest_prefetch() returns
  /// Whether a smoother call (`trial`: one that may time the choice) or a
  /// residual on `level` prefetches the next block (`on`), and whether the
  /// level's PrefetchTrial decides it (`timed`).
  struct PrefetchChoice {
    bool on = false;
    bool timed = false;
  };
  PrefetchChoice prefetching(int level, const BlockField& x, const BlockField& rhs, bool trial);
};

}  // namespace sanguis::flow
