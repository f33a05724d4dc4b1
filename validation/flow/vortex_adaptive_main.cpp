// Driver of the adaptive vortex validation (issue #7): a shielded vortex
// carried by a uniform stream once across a periodic box, on uniform grids
// and on a grid that follows it (the wavelet criterion, thesis eq. 4.11, on
// the velocity), with a passive tracer in its core.
//
//   validate_vortex_adaptive OUTDIR [--threads T] [--zeta Z1,Z2,..] [--uniform yes|no]
//                            [--geometry plane|tilted] [--level-matched yes|no]
//
// The box is the unit square, periodic in x and y, one tree (1/4) thick and
// periodic in z; blocks of 8^3 cells; levels 0, 1, 2 give 32^2, 64^2 and
// 128^2 cells in the plane. The vortex is the Gaussian stream function
// psi = A exp(-r^2 / (2 sigma^2)) (sigma = 0.05, peak swirl 0.5 m/s; zero
// net circulation, so it is periodic to round-off), an exact steady solution
// of the Euler equations; with U = (1, 0, 0) and no viscosity the exact
// field at t = 1 is the initial one. Every run takes the same time step
// (CFL 0.8 of the finest grid), so that only the grids differ.
//
// --geometry tilted: the 3D version. The box is the unit cube (4^3 trees,
// 32^3 to 128^3 cells) and the vortex is a column whose axis runs along
// (1, 0, 1)/sqrt(2) through the box (it closes on itself through the periodic
// faces after a length sqrt(2); its images are 0.71 = 14 sigma apart, so the
// nearest image changes 7.1 sigma from the axis, where the Gaussian is
// 1.4e-11: the field is periodic and steady to about 1e-10 m/s), with the
// same profile across the axis: an exact steady Euler solution to that
// level, carried by the same stream along x. Its
// refined region is a tilted tube, so the coarse-fine faces it crosses face
// all three directions.
//
// Writes OUTDIR/vortex_adaptive.csv (one row per run: errors against the
// exact field, the far-field disturbance, cells, tracer drift, wall time)
// and OUTDIR/vortex_profiles.csv (v along the line y = 0.5 through the
// vortex at t = 1, per run). validation/flow/vortex_adaptive.py checks and
// plots them.
#include <omp.h>

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

constexpr double kSigma = 0.05;
constexpr double kSwirl = 0.5;  // peak swirl speed (m/s), at r = sigma
const Vec3 kStream{1.0, 0.0, 0.0};
const Vec3 kStart{0.5, 0.5, 0.0};
constexpr double kEnd = 1.0;     // one crossing of the box
constexpr int kFinestLevel = 2;  // every run steps at the CFL step of 128^2
bool g_level_matched = false;  // --level-matched yes: NavierStokesOptions::level_matched_advection
bool g_tilted = false;         // --geometry tilted: the 3D column along kAxis
const Vec3 kAxis{1.0 / std::sqrt(2.0), 0.0, 1.0 / std::sqrt(2.0)};

/// x - centre across the vortex axis, to the nearest periodic image: in the
/// plane, the nearest image of x - centre; tilted, the component normal to
/// kAxis, the shortest over the images of the nearest 27 boxes.
Vec3 offset(const Vec3& x, const Vec3& centre) {
  Vec3 r{x.x - centre.x, x.y - centre.y, g_tilted ? x.z - centre.z : 0.0};
  r.x -= std::round(r.x);
  r.y -= std::round(r.y);
  r.z -= std::round(r.z);
  if (!g_tilted) return r;
  Vec3 best{1e9, 1e9, 1e9};
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        const Vec3 image = r + Vec3{double(i), double(j), double(k)};
        const Vec3 across = image - dot(image, kAxis) * kAxis;
        if (dot(across, across) < dot(best, best)) best = across;
      }
  return best;
}

/// Exact velocity at time t: the vortex at kStart + U t in the stream.
Vec3 exact(const Vec3& x, double t) {
  const Vec3 r = offset(x, kStart + t * kStream);
  const double amplitude = kSwirl * kSigma * std::exp(0.5);  // A: peak swirl at r = sigma
  const double g = amplitude / (kSigma * kSigma) * std::exp(-dot(r, r) / (2 * kSigma * kSigma));
  // u = d psi/dy, v = -d psi/dx with psi = A exp(-r^2 / 2 sigma^2): in the
  // plane g (z x r), about the tilted axis g (axis x r).
  if (g_tilted) return kStream + g * cross(kAxis, r);
  return kStream + Vec3{-r.y * g, r.x * g, 0.0};
}

double tracer0(const Vec3& x) {
  const Vec3 r = offset(x, kStart);
  return std::exp(-dot(r, r) / (2 * kSigma * kSigma));
}

struct RunResult {
  std::string name;
  double cells_mean = 0.0, cells_end = 0.0, cells_uniform_finest = 0.0;
  double max_error = 0.0, rms_error = 0.0;  ///< velocity against the exact field (m/s)
  double far_field = 0.0;  ///< max |u - U| at r > 4 sigma from the exact centre (m/s)
  double tracer_drift = 0.0;
  double max_divergence = 0.0;
  double seconds = 0.0;
  int steps = 0;
  std::vector<std::pair<double, double>> profile;  ///< (x, v) along y = 0.5 at t = 1
};

double total(const Forest& forest, const BlockField& c) {
  const int b = forest.block_cells();
  double sum = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const double h = forest.block(blk).length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) sum += c(blk, i, j, k) * h * h * h;
  }
  return forest.sum(sum);
}

Vec3 centre_of(const Block& block, int b, int i, int j, int k) {
  const double h = block.length / b;
  return {block.lower.x + (i + 0.5) * h, block.lower.y + (j + 0.5) * h,
          block.lower.z + (k + 0.5) * h};
}

/// One run: uniform at `min_level` when min_level == max_level, else adaptive.
RunResult run(const std::string& name, int min_level, int max_level, double zeta, int threads) {
  Forest forest(validation::periodic_box({4, 4, g_tilted ? 4 : 1}, min_level, threads));
  NavierStokesOptions options = validation::tight_solves();
  options.level_matched_advection = g_level_matched;
  NavierStokes ns(forest, validation::periodic_boundaries(), Fluid{1.0, 0.0}, options);
  const auto initial = [](const Vec3& x) { return exact(x, 0.0); };
  ns.set_velocity(initial);
  BlockField tracer(forest.local_blocks(), forest.block_cells());
  const auto fill_tracer = [&]() {
    tracer = BlockField(forest.local_blocks(), forest.block_cells());
    const int b = forest.block_cells();
    for (int blk = 0; blk < forest.local_blocks(); ++blk)
      for (int k = 0; k < b; ++k)
        for (int j = 0; j < b; ++j)
          for (int i = 0; i < b; ++i)
            tracer(blk, i, j, k) = tracer0(centre_of(forest.block(blk), b, i, j, k));
  };
  const bool adaptive = max_level > min_level;
  const WaveletCriterion criterion{{zeta, zeta, zeta}, min_level, max_level};
  if (adaptive) validation::initial_grid(ns, forest, criterion, initial);
  fill_tracer();
  const double mass0 = total(forest, tracer);
  const double b3 = std::pow(forest.block_cells(), 3);
  const double dt = 0.8 / (8.0 * 4 * (1 << kFinestLevel)) / (1.0 + kSwirl);
  const int steps = static_cast<int>(std::ceil(kEnd / dt - 1e-9));
  RunResult r;
  r.name = name;
  r.steps = steps;
  const auto start = std::chrono::steady_clock::now();
  double cell_sum = 0.0;
  for (int s = 0; s < steps; ++s) {
    if (adaptive && s > 0 && s % 2 == 0) {
      BlockField* scalars[] = {&tracer};
      validation::regrid_on_velocity(ns, forest, criterion, scalars);
    }
    const double step = std::min(dt, kEnd - ns.time());
    ns.step(step);
    ns.advect_scalar(tracer, step);
    cell_sum += static_cast<double>(forest.global_blocks()) * b3;
    r.max_divergence = std::max(r.max_divergence, ns.max_divergence());
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.cells_mean = cell_sum / steps;
  r.cells_end = static_cast<double>(forest.global_blocks()) * b3;
  const auto& trees = forest.spec().trees;
  r.cells_uniform_finest = double(trees[0]) * trees[1] * trees[2] * std::pow(8.0, max_level) * b3;
  r.tracer_drift = std::abs(total(forest, tracer) / mass0 - 1.0);
  const int b = forest.block_cells();
  const Vec3 centre = kStart + ns.time() * kStream;
  double sum2 = 0.0, volume = 0.0;
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const Block& block = forest.block(blk);
    const double h = block.length / b;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const Vec3 x = centre_of(block, b, i, j, k);
          const Vec3 u{ns.velocity()[0](blk, i, j, k), ns.velocity()[1](blk, i, j, k),
                       ns.velocity()[2](blk, i, j, k)};
          const Vec3 e = u - exact(x, ns.time());
          r.max_error = std::max(r.max_error, norm(e));
          sum2 += dot(e, e) * h * h * h;
          volume += h * h * h;
          const Vec3 d = offset(x, centre);
          if (std::sqrt(dot(d, d)) > 4 * kSigma) {
            r.far_field = std::max(r.far_field, norm(u - kStream));
          }
          // v on the cells next to the plane y = 0.5 (and the lowest z layer).
          if (k == 0 && block.lower.z == 0.0 && std::abs(x.y - 0.5) < 0.5 * h + 1e-12 &&
              x.y > 0.5) {
            r.profile.emplace_back(x.x, u.y);
          }
        }
  }
  r.max_error = forest.max(r.max_error);
  r.rms_error = std::sqrt(forest.sum(sum2) / forest.sum(volume));
  r.far_field = forest.max(r.far_field);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: validate_vortex_adaptive OUTDIR [--threads T] [--zeta Z1,Z2,..] "
                 "[--uniform yes|no] [--geometry plane|tilted] [--level-matched yes|no]\n";
    return 2;
  }
  MpiSession::ensure();
  const std::filesystem::path out_dir = argv[1];
  int threads = 1;
  std::vector<double> zetas{2e-3, 5e-3, 1e-2};
  bool uniform = true;
  for (int a = 2; a + 1 < argc; a += 2) {
    const std::string key = argv[a];
    if (key == "--threads") {
      threads = std::atoi(argv[a + 1]);
    } else if (key == "--zeta") {  // comma-separated thresholds, one adaptive run each
      zetas.clear();
      std::string list = argv[a + 1];
      for (std::size_t at = 0; at <= list.size();) {
        const std::size_t comma = std::min(list.find(',', at), list.size());
        zetas.push_back(std::atof(list.substr(at, comma - at).c_str()));
        at = comma + 1;
      }
    } else if (key == "--geometry") {  // plane (default) or tilted (3D)
      const std::string geometry = argv[a + 1];
      if (geometry != "plane" && geometry != "tilted") {
        std::cerr << "--geometry: plane or tilted, not " << geometry << "\n";
        return 2;
      }
      g_tilted = geometry == "tilted";
    } else if (key == "--uniform") {  // yes (default) or no: skip the uniform runs
      uniform = std::string(argv[a + 1]) != "no";
    } else if (key == "--level-matched") {  // no (default) or yes; the runs' names say it
      const std::string value = argv[a + 1];
      if (value != "yes" && value != "no") {
        std::cerr << "--level-matched: yes or no, not " << value << "\n";
        return 2;
      }
      g_level_matched = value == "yes";
    } else {
      std::cerr << "unknown option " << key << "\n";
      return 2;
    }
  }
  std::filesystem::create_directories(out_dir);
  struct Spec {
    std::string name;
    int min_level, max_level;
    double zeta;
  };
  std::vector<Spec> runs;
  if (uniform) {
    const std::string power = g_tilted ? "^3" : "^2";
    for (int level = 0; level <= kFinestLevel; ++level) {
      runs.push_back({"uniform " + std::to_string(32 << level) + power, level, level, 0.0});
    }
  }
  for (const double zeta : zetas) {
    char name[64];
    std::snprintf(name, sizeof name, "adaptive zeta %g%s", zeta,
                  g_level_matched ? " (level-matched)" : "");
    runs.push_back({name, 0, 2, zeta});
  }
  std::vector<RunResult> results;
  std::vector<double> run_zeta;
  for (const Spec& spec : runs) {
    results.push_back(run(spec.name, spec.min_level, spec.max_level, spec.zeta, threads));
    run_zeta.push_back(spec.zeta);
    const RunResult& r = results.back();
    std::printf(
        "%-20s cells %8.0f (mean) %8.0f (end), max error %.3e, RMS %.3e, far field %.2e, tracer "
        "drift %.1e, max |div| %.1e, %d steps, %.1f s\n",
        r.name.c_str(), r.cells_mean, r.cells_end, r.max_error, r.rms_error, r.far_field,
        r.tracer_drift, r.max_divergence, r.steps, r.seconds);
    std::fflush(stdout);
  }
  // Without the uniform runs the new rows are added to an existing table.
  const bool append = !uniform && std::filesystem::exists(out_dir / "vortex_adaptive.csv");
  std::ofstream csv(out_dir / "vortex_adaptive.csv", append ? std::ios::app : std::ios::trunc);
  csv.precision(8);
  if (!append) {
    csv << "run,cells_mean,cells_end,cells_uniform_finest,max_error,rms_error,far_field,tracer_"
           "drift,max_divergence,steps,seconds,zeta,threads\n";
  }
  for (std::size_t n = 0; n < results.size(); ++n) {
    const RunResult& r = results[n];
    csv << r.name << ',' << r.cells_mean << ',' << r.cells_end << ',' << r.cells_uniform_finest
        << ',' << r.max_error << ',' << r.rms_error << ',' << r.far_field << ',' << r.tracer_drift
        << ',' << r.max_divergence << ',' << r.steps << ',' << r.seconds << ',' << run_zeta[n]
        << ',' << threads << '\n';
  }
  std::ofstream profiles(out_dir / "vortex_profiles.csv", append ? std::ios::app : std::ios::trunc);
  if (!append) profiles << "run,x,v\n";
  profiles.precision(10);
  for (const RunResult& r : results)
    for (const auto& [x, v] : r.profile) profiles << r.name << ',' << x << ',' << v << '\n';
  std::cout << "wrote " << (out_dir / "vortex_adaptive.csv") << '\n';
  return 0;
}
