// Driver of the adaptive Taylor-Green validation (issue #7): the classic 3D
// Taylor-Green vortex (Taylor & Green 1937; Brachet et al. 1983) decaying in
// the periodic unit cube at Re = 100, on uniform grids of 32^3, 64^3 and
// 128^3 cells and on a grid between 32^3 and 128^3 set by the wavelet
// criterion (thesis eq. 4.11) on the velocity.
//
//   validate_taylor_green_adaptive OUTDIR [--threads T] [--zeta Z] [--uniform yes|no]
//                                  [--block-cells B] [--level-matched yes|no]
//
// The initial field, wave number k = 2 pi, u0 = 1 m/s,
//
//   u = u0 sin(kx) cos(ky) cos(kz),  v = -u0 cos(kx) sin(ky) cos(kz),  w = 0,
//
// is divergence-free; it is not a steady solution: vortex stretching moves
// energy to smaller scales until the dissipation peaks (t k u0 about 5 at
// Re = 100, t about 0.8 s here) and the flow decays. Re = u0 / (k nu) = 100,
// so nu = 1 / (200 pi) m^2/s. Every run takes the same fixed time step (CFL
// 0.8 of the 128^3 grid at u0, 1/160 s) to t = 1.5 s, so that only the grids
// differ.
//
// The uniform 128^3 run is the reference: its cell velocities at t = 0.75
// and 1.5 s are kept (OUTDIR/reference_step120.bin and reference_step240.bin, raw doubles,
// component-major, x fastest) and every other run is compared, cell by cell, with the reference's
// mean over each of its cells. With --uniform no, the uniform runs are skipped and the reference is
// read back from those files.
//
// --block-cells 4 (default 8) builds the adaptive grid from 4^3-cell blocks, 8^3
// trees of 1/8 m instead of 4^3 trees of 1/4 m: the same cells, refined and
// coarsened in units of 4^3 cells instead of 8^3 (the criterion decides per
// block). The run's name then ends in " (4^3 blocks)"; it needs --uniform no.
//
// --level-matched yes runs the adaptive grid with
// NavierStokesOptions::level_matched_advection (the uniform grids are the same
// either way); the run's name then ends in " (level-matched)".
//
// Writes OUTDIR/taylor_green_adaptive.csv (one row per run: cells, cell
// differences against the reference, wall time), OUTDIR/taylor_green_history.csv
// (per run, every 8 steps: time, kinetic energy per unit mass, cells) and
// OUTDIR/taylor_green_slice.csv (per run, the cells of the layer at z = 0
// at t = 1.5: lower corner, size, |difference|). validation/flow/
// taylor_green_adaptive.py checks and plots them. The summary line of each run
// also names, per compared time, its worst cell: centre, level, and how many
// cells lie between it and the nearest face of its block with a level jump.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "flow/adapt_criterion.hpp"
#include "flow/mpi_session.hpp"
#include "flow/navier_stokes.hpp"
#include "periodic_box.hpp"

using namespace sanguis;
using namespace sanguis::flow;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kWave = 2.0 * kPi;
constexpr double kSpeed = 1.0;                        // u0 (m/s)
constexpr double kViscosity = 1.0 / (100.0 * kWave);  // Re = u0 / (k nu) = 100
constexpr int kFinestLevel = 2;                       // 32^3 cells at level 0: 128^3
constexpr int kFinestCells = 128;
constexpr double kStep = 0.8 / kFinestCells / kSpeed;  // CFL 0.8 of the finest grid
constexpr int kSteps = 240;                            // t = 1.5 s
constexpr int kHistoryEvery = 8;
constexpr int kRegridEvery = 4;
const std::vector<int> kCompareSteps{120, 240};  // t = 0.75 and 1.5 s

Vec3 initial_velocity(const Vec3& x) {
  const double cz = std::cos(kWave * x.z);
  return {kSpeed * std::sin(kWave * x.x) * std::cos(kWave * x.y) * cz,
          -kSpeed * std::cos(kWave * x.x) * std::sin(kWave * x.y) * cz, 0.0};
}

/// The reference's cell velocities on the uniform finest grid at one time:
/// value(c, i, j, k) at [(c * n + k) * n + j) * n + i].
/// Gathered from the local blocks: the driver runs as one process.
struct Snapshot {
  int n = kFinestCells;
  std::vector<double> values = std::vector<double>(3 * std::size_t(n) * n * n, 0.0);
  static std::size_t index(int c, int i, int j, int k) {
    constexpr std::size_t m = kFinestCells;
    return ((std::size_t(c) * m + std::size_t(k)) * m + std::size_t(j)) * m + std::size_t(i);
  }
  double at(int c, int i, int j, int k) const { return values[index(c, i, j, k)]; }
};

std::filesystem::path snapshot_path(const std::filesystem::path& dir, int step) {
  return dir / ("reference_step" + std::to_string(step) + ".bin");
}

Snapshot take_snapshot(const Forest& forest, const NavierStokes& ns) {
  Snapshot s;
  const int b = forest.block_cells();
  const double h = 1.0 / s.n;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const int i0 = static_cast<int>(std::lround(block.lower.x / h));
    const int j0 = static_cast<int>(std::lround(block.lower.y / h));
    const int k0 = static_cast<int>(std::lround(block.lower.z / h));
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i)
            s.values[Snapshot::index(c, i0 + i, j0 + j, k0 + k)] =
                ns.velocity()[std::size_t(c)](blk, i, j, k);
  }
  return s;
}

void write_snapshot(const Snapshot& s, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(s.values.data()),
            static_cast<std::streamsize>(s.values.size() * sizeof(double)));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

Snapshot read_snapshot(const std::filesystem::path& path) {
  Snapshot s;
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(s.values.data()),
          static_cast<std::streamsize>(s.values.size() * sizeof(double)));
  if (!in) {
    throw std::runtime_error(path.string() +
                             ": cannot read the reference (run with the uniform runs first)");
  }
  return s;
}

struct Comparison {
  double max = 0.0, rms = 0.0;  ///< |u - mean of the reference over the cell|, largest component
  /// The worst cell (one process): its centre, level, and its distance in its own
  /// cells to the nearest face of its block with a coarser or finer block across
  /// (-1: none; 0: the cell touches it).
  Vec3 worst_at{};
  int worst_level = 0;
  int worst_from_level_jump = -1;
};

/// Cells between cell (i, j, k) of block `block` (b cells per edge) and the
/// nearest of the block's faces with a level jump across, -1 if none.
int cells_from_level_jump(const Block& block, int b, int i, int j, int k) {
  const int n[3] = {i, j, k};
  int nearest = -1;
  for (int d = 0; d < 3; ++d)
    for (int side = 0; side < 2; ++side) {
      const Neighbour& nb = block.neighbours[face_neighbour_slot(d, side)];
      if (nb.link == Link::Boundary || nb.jump == LevelJump::Same) continue;
      const int distance = side == 0 ? n[d] : b - 1 - n[d];
      if (nearest < 0 || distance < nearest) nearest = distance;
    }
  return nearest;
}

struct SliceCell {
  double x, y, h, difference;
};

/// Every cell against the reference's mean over it; `slice` gets the cells
/// of the layer at z = 0 when not null.
Comparison compare(const Forest& forest, const NavierStokes& ns, const Snapshot& reference,
                   std::vector<SliceCell>* slice) {
  Comparison result;
  const int b = forest.block_cells();
  const double hf = 1.0 / reference.n;
  double sum2 = 0.0, volume = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    const int r = static_cast<int>(std::lround(h / hf));  // reference cells per cell and axis
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const int fi = static_cast<int>(std::lround(block.lower.x / hf)) + i * r;
          const int fj = static_cast<int>(std::lround(block.lower.y / hf)) + j * r;
          const int fk = static_cast<int>(std::lround(block.lower.z / hf)) + k * r;
          double worst = 0.0;
          for (int c = 0; c < 3; ++c) {
            double mean = 0.0;
            for (int kk = 0; kk < r; ++kk)
              for (int jj = 0; jj < r; ++jj)
                for (int ii = 0; ii < r; ++ii) mean += reference.at(c, fi + ii, fj + jj, fk + kk);
            mean /= double(r) * r * r;
            worst = std::max(worst, std::abs(ns.velocity()[std::size_t(c)](blk, i, j, k) - mean));
          }
          if (worst > result.max) {
            result.max = worst;
            result.worst_at = {block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
                               block.lower.z + (k + 0.5) * h};
            result.worst_level = block.level;
            result.worst_from_level_jump = cells_from_level_jump(block, b, i, j, k);
          }
          sum2 += worst * worst * h * h * h;
          volume += h * h * h;
          if (slice && fk == 0) {
            slice->push_back({block.lower.x + i * h, block.lower.y + j * h, h, worst});
          }
        }
  }
  result.max = forest.max(result.max);
  result.rms = std::sqrt(forest.sum(sum2) / forest.sum(volume));
  return result;
}

double kinetic_energy(const Forest& forest, const NavierStokes& ns) {
  const int b = forest.block_cells();
  double sum = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          double u2 = 0.0;
          for (int c = 0; c < 3; ++c) {
            const double u = ns.velocity()[std::size_t(c)](blk, i, j, k);
            u2 += u * u;
          }
          sum += 0.5 * u2 * h * h * h;
        }
  }
  return forest.sum(sum);  // per unit mass: the box has unit volume
}

struct HistoryRow {
  double time, energy, cells;
};

struct RunResult {
  std::string name;
  double zeta = 0.0;
  double cells_mean = 0.0, cells_max = 0.0, cells_end = 0.0;
  std::vector<Comparison> comparisons;  ///< at kCompareSteps (empty for the reference)
  double max_divergence = 0.0;
  double seconds = 0.0;
  double regrid_seconds = 0.0;  ///< of `seconds`, in the regrids
  /// V-cycles per step: final projection, predictor projection, the three viscous solves.
  double pressure_cycles = 0.0, predictor_cycles = 0.0, viscous_cycles = 0.0;
  std::vector<HistoryRow> history;
  std::vector<SliceCell> slice;
};

/// One run: uniform at `min_level` when min_level == max_level, else
/// adaptive. The reference run (uniform at the finest level) fills
/// `references`; the others are compared with them.
RunResult run(const std::string& name, int min_level, int max_level, double zeta, int threads,
              int block_cells, bool level_matched, std::vector<Snapshot>& references,
              const std::filesystem::path& out_dir) {
  const int trees = kFinestCells / 4 / block_cells;  // 32^3 cells at level 0
  Forest forest(validation::periodic_box({trees, trees, trees}, min_level, threads, block_cells,
                                         1.0 / trees));
  if (forest.ranks() > 1) {
    throw std::runtime_error("one process only: the reference snapshot holds the local blocks");
  }
  NavierStokesOptions options = validation::tight_solves();
  options.level_matched_advection = level_matched;
  NavierStokes ns(forest, validation::periodic_boundaries(), Fluid{1.0, kViscosity}, options);
  ns.set_velocity(initial_velocity);
  const bool adaptive = max_level > min_level;
  const bool reference = !adaptive && min_level == kFinestLevel;
  const WaveletCriterion criterion{{zeta, zeta, zeta}, min_level, max_level};
  if (adaptive) validation::initial_grid(ns, forest, criterion, initial_velocity);
  const double b3 = std::pow(forest.block_cells(), 3);
  RunResult r;
  r.name = name;
  r.zeta = zeta;
  const auto record = [&]() {
    r.history.push_back({ns.time(), kinetic_energy(forest, ns), forest.global_blocks() * b3});
  };
  record();
  const auto start = std::chrono::steady_clock::now();
  double cell_sum = 0.0;
  for (int s = 1; s <= kSteps; ++s) {
    if (adaptive && s > 1 && (s - 1) % kRegridEvery == 0) {
      const auto regrid_start = std::chrono::steady_clock::now();
      validation::regrid_on_velocity(ns, forest, criterion);
      r.regrid_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - regrid_start).count();
    }
    const StepReport report = ns.step(kStep);
    r.pressure_cycles += report.pressure_cycles / double(kSteps);
    r.predictor_cycles += report.predictor_cycles / double(kSteps);
    r.viscous_cycles += report.viscous_cycles / double(kSteps);
    const double cells = forest.global_blocks() * b3;
    cell_sum += cells;
    r.cells_max = std::max(r.cells_max, cells);
    r.max_divergence = std::max(r.max_divergence, ns.max_divergence());
    if (s % kHistoryEvery == 0) record();
    for (std::size_t n = 0; n < kCompareSteps.size(); ++n) {
      if (s != kCompareSteps[n]) continue;
      if (reference) {
        references.push_back(take_snapshot(forest, ns));
        write_snapshot(references.back(), snapshot_path(out_dir, s));
      } else {
        const bool last = s == kSteps;
        r.comparisons.push_back(compare(forest, ns, references[n], last ? &r.slice : nullptr));
      }
    }
    if (s % 40 == 0) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("  %s: step %d/%d, t = %.3f s, %.0f cells, %.0f s, ETA %.0f s\n", name.c_str(), s,
                  kSteps, ns.time(), cells, elapsed, elapsed / s * (kSteps - s));
      std::fflush(stdout);
    }
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cells_mean = cell_sum / kSteps;
  r.cells_end = forest.global_blocks() * b3;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: validate_taylor_green_adaptive OUTDIR [--threads T] [--zeta Z] "
                 "[--uniform yes|no] [--block-cells B] [--level-matched yes|no]\n";
    return 2;
  }
  MpiSession::ensure();
  const std::filesystem::path out_dir = argv[1];
  int threads = 1;
  double zeta = 1e-2;
  bool uniform = true;
  int block_cells = 8;
  std::string level_matched = "no";
  if ((argc - 2) % 2 != 0) {  // an option without its value
    std::cerr << "every option takes a value: " << argv[argc - 1] << " has none\n";
    return 2;
  }
  for (int a = 2; a + 1 < argc; a += 2) {
    const std::string key = argv[a];
    if (key == "--threads") {
      threads = std::atoi(argv[a + 1]);
    } else if (key == "--zeta") {
      zeta = std::atof(argv[a + 1]);
    } else if (key == "--uniform") {  // yes (default) or no: read the reference back
      uniform = std::string(argv[a + 1]) != "no";
    } else if (key == "--block-cells") {  // "4" or "8" exactly (checked below)
      const std::string value = argv[a + 1];
      block_cells = value == "4" ? 4 : value == "8" ? 8 : 0;
    } else if (key == "--level-matched") {  // "no" (default) or "yes" (checked below)
      level_matched = argv[a + 1];
    } else {
      std::cerr << "unknown option " << key << "\n";
      return 2;
    }
  }
  if (!(zeta > 0.0)) {
    std::cerr << "--zeta: a positive threshold in m/s\n";
    return 2;
  }
  if (block_cells != 4 && block_cells != 8) {
    std::cerr << "--block-cells: 4 or 8 (cells per block edge)\n";
    return 2;
  }
  if (level_matched != "yes" && level_matched != "no") {
    std::cerr << "--level-matched: yes or no, not " << level_matched << "\n";
    return 2;
  }
  if (block_cells != 8 && uniform) {  // the uniform runs would take the reference's names
    std::cerr << "--block-cells 4: adaptive runs only, against the reference on disk "
                 "(give --uniform no)\n";
    return 2;
  }
  std::filesystem::create_directories(out_dir);
  struct Spec {
    std::string name;
    int min_level, max_level;
    double zeta;
  };
  std::vector<Spec> runs;
  std::vector<Snapshot> references;
  if (uniform) {
    for (int level = kFinestLevel; level >= 0; --level) {  // the reference first
      runs.push_back({"uniform " + std::to_string(32 << level) + "^3", level, level, 0.0});
    }
  } else {
    try {
      for (const int s : kCompareSteps)
        references.push_back(read_snapshot(snapshot_path(out_dir, s)));
    } catch (const std::exception& e) {
      std::cerr << e.what() << "\n";
      return 1;
    }
  }
  char name[64];
  std::snprintf(name, sizeof name, "adaptive zeta %g%s%s", zeta,
                block_cells == 8 ? "" : " (4^3 blocks)",
                level_matched == "yes" ? " (level-matched)" : "");
  runs.push_back({name, 0, kFinestLevel, zeta});
  std::vector<RunResult> results;
  for (const Spec& spec : runs) {
    try {
      results.push_back(run(spec.name, spec.min_level, spec.max_level, spec.zeta, threads,
                            block_cells, level_matched == "yes", references, out_dir));
    } catch (const std::exception& e) {
      std::cerr << spec.name << ": " << e.what() << "\n";
      return 1;
    }
    const RunResult& r = results.back();
    std::printf("%-20s cells %9.0f (mean) %9.0f (max) %9.0f (end), max |div| %.1e, %.1f s",
                r.name.c_str(), r.cells_mean, r.cells_max, r.cells_end, r.max_divergence,
                r.seconds);
    for (std::size_t n = 0; n < r.comparisons.size(); ++n) {
      std::printf(", step %d: max %.3e RMS %.3e", kCompareSteps[n], r.comparisons[n].max,
                  r.comparisons[n].rms);
    }
    for (std::size_t n = 0; n < r.comparisons.size(); ++n) {
      const Comparison& c = r.comparisons[n];
      std::printf(
          "\n  step %d: worst cell at (%.4f, %.4f, %.4f), level %d, %d cells from a level jump "
          "of its block's faces (-1: none)",
          kCompareSteps[n], c.worst_at.x, c.worst_at.y, c.worst_at.z, c.worst_level,
          c.worst_from_level_jump);
    }
    std::printf(", V-cycles per step %.2f + %.2f + %.2f, regrid %.1f s\n", r.pressure_cycles,
                r.predictor_cycles, r.viscous_cycles, r.regrid_seconds);
    std::fflush(stdout);
  }
  const auto mode = uniform ? std::ios::trunc : std::ios::app;
  const bool header = uniform || !std::filesystem::exists(out_dir / "taylor_green_adaptive.csv");
  std::ofstream csv(out_dir / "taylor_green_adaptive.csv", mode);
  std::ofstream history(out_dir / "taylor_green_history.csv", mode);
  std::ofstream slice(out_dir / "taylor_green_slice.csv", mode);
  csv.precision(8);
  history.precision(12);
  slice.precision(8);
  if (header) {
    csv << "run,zeta,cells_mean,cells_max,cells_end,cells_uniform_finest,max_mid,rms_mid,max_end,"
           "rms_end,max_divergence,steps,seconds,threads,regrid_seconds,pressure_cycles,predictor_"
           "cycles,viscous_cycles\n";
    history << "run,time,kinetic_energy,cells\n";
    slice << "run,x,y,h,difference\n";
  }
  const double finest = std::pow(double(kFinestCells), 3);
  for (const RunResult& r : results) {
    csv << r.name << ',' << r.zeta << ',' << r.cells_mean << ',' << r.cells_max << ','
        << r.cells_end << ',' << finest;
    for (std::size_t n = 0; n < kCompareSteps.size(); ++n) {
      if (r.comparisons.empty()) {
        csv << ",0,0";
      } else {
        csv << ',' << r.comparisons[n].max << ',' << r.comparisons[n].rms;
      }
    }
    csv << ',' << r.max_divergence << ',' << kSteps << ',' << r.seconds << ',' << threads << ','
        << r.regrid_seconds << ',' << r.pressure_cycles << ',' << r.predictor_cycles << ','
        << r.viscous_cycles << '\n';
    for (const HistoryRow& h : r.history)
      history << r.name << ',' << h.time << ',' << h.energy << ',' << h.cells << '\n';
    for (const SliceCell& c : r.slice)
      slice << r.name << ',' << c.x << ',' << c.y << ',' << c.h << ',' << c.difference << '\n';
  }
  std::cout << "wrote " << (out_dir / "taylor_green_adaptive.csv") << '\n';
  return 0;
}
