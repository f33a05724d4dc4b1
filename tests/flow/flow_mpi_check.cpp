// Run under `mpirun -np 2`: the multigrid Poisson solution on the forest
// shared by both ranks must equal the one-rank solution (MPI_COMM_SELF) to
// round-off. Exit status 0 when it does.
#include <cmath>
#include <cstdio>
#include <vector>

#include "flow/mpi_session.hpp"
#include "flow/navier_stokes.hpp"
#include "poisson_problems.hpp"

namespace {

using namespace sanguis::flow;

/// Every cell's value in a global array (zero elsewhere), summed over ranks.
std::vector<double> gathered(const Forest& forest, const BlockField& field) {
  const int b = forest.block_cells();
  const auto nb = forest.blocks_per_direction(forest.spec().level);
  const std::int64_t nx = nb[0] * b, ny = nb[1] * b, nz = nb[2] * b;
  std::vector<double> all(static_cast<std::size_t>(nx * ny * nz), 0.0);
  for (int blk = 0; blk < forest.local_blocks(); ++blk) {
    const auto& c = forest.block(blk).coord;
    for (int k = 0; k < b; ++k)
      for (int j = 0; j < b; ++j)
        for (int i = 0; i < b; ++i) {
          const std::int64_t g = ((c[2] * b + k) * ny + c[1] * b + j) * nx + c[0] * b + i;
          all[static_cast<std::size_t>(g)] = field(blk, i, j, k);
        }
  }
  MPI_Allreduce(MPI_IN_PLACE, all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_SUM,
                forest.comm());
  return all;
}

int check(bool periodic) {
  // Fixed number of cycles (tolerance 0) so both runs do the same work.
  const int cells = 16;
  auto run = [&](MPI_Comm comm, std::vector<double>& values) {
    ForestSpec spec;
    spec.periodic = {periodic, periodic, periodic};
    spec.level = 1;
    spec.comm = comm;
    const Forest forest(spec);
    auto result = testing::solve_manufactured(periodic, cells, comm, 1e-13);
    // Re-gather on a forest with the same partition as the solve.
    values = gathered(forest, result.solution);
    return result;
  };
  std::vector<double> shared, alone;
  const auto r2 = run(MPI_COMM_WORLD, shared);
  const auto r1 = run(MPI_COMM_SELF, alone);
  double diff = 0.0;
  for (std::size_t i = 0; i < shared.size(); ++i)
    diff = std::max(diff, std::abs(shared[i] - alone[i]));
  const auto& session = MpiSession::ensure();
  if (session.rank() == 0) {
    std::printf("%s: %d ranks vs 1: max difference %.3e, errors %.6e / %.6e, cycles %d / %d\n",
                periodic ? "periodic" : "Dirichlet", session.size(), diff, r2.error, r1.error,
                r2.report.cycles, r1.report.cycles);
  }
  return diff <= 1e-11 ? 0 : 1;
}

/// Ten steps of the Re = 100 cavity (16^3, 8 blocks) on the shared forest and alone.
int check_navier_stokes() {
  auto run = [](MPI_Comm comm) {
    ForestSpec spec;
    spec.level = 1;
    spec.comm = comm;
    const Forest forest(spec);
    std::array<FlowBoundary, 6> bcs{};
    bcs[face_index(1, 1)].wall_velocity = {1.0, 0.0, 0.0};
    NavierStokesOptions options;
    options.pressure.tolerance = 1e-10;
    options.viscous.tolerance = 1e-10;
    NavierStokes ns(forest, bcs, Fluid{1.0, 0.01}, options);
    ns.set_velocity([](const sanguis::Vec3&) { return sanguis::Vec3{}; });
    for (int s = 0; s < 10; ++s) ns.step(0.02);
    std::array<std::vector<double>, 4> values;
    for (int c = 0; c < 3; ++c)
      values[static_cast<std::size_t>(c)] =
          gathered(forest, ns.velocity()[static_cast<std::size_t>(c)]);
    values[3] = gathered(forest, ns.pressure());
    return values;
  };
  const auto shared = run(MPI_COMM_WORLD);
  const auto alone = run(MPI_COMM_SELF);
  double diff = 0.0, scale = 0.0;
  for (std::size_t f = 0; f < 4; ++f)
    for (std::size_t i = 0; i < shared[f].size(); ++i) {
      diff = std::max(diff, std::abs(shared[f][i] - alone[f][i]));
      scale = std::max(scale, std::abs(alone[f][i]));
    }
  const auto& session = MpiSession::ensure();
  if (session.rank() == 0) {
    std::printf(
        "cavity 16^3, 10 steps: %d ranks vs 1: max difference of u and p %.3e (max |value| %.3f)\n",
        session.size(), diff, scale);
  }
  return diff <= 1e-11 ? 0 : 1;
}

}  // namespace

int main() {
  MpiSession::ensure();
  const int failures = check(true) + check(false) + check_navier_stokes();
  return failures == 0 ? 0 : 1;
}
