// `mpirun -np 2 sanguis run CASE` end to end: the decomposed run writes one block per
// process in each .pvd, and `sanguis analyze` reads them back into exactly the numbers
// of the one-process run (the particle states are bitwise equal, see
// tests/dem/dem_mpi_check.cpp; the contact network is split by owner of the first
// particle and reassembled). Skipped where no mpirun is installed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "cli_harness.hpp"

namespace sanguis {
namespace {

using testing_cli::read_text_file;
using testing_cli::SanguisCommandTest;
using testing_cli::shell_quoted;

class MpiRun : public SanguisCommandTest {};

TEST_F(MpiRun, TwoProcessesAnalyseLikeOne) {
  if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const std::string tiny =
      std::string(SANGUIS_SOURCE_DIR) + "/tests/integration/data/dam-break-tiny.toml";
  ASSERT_EQ(sanguis("run " + shell_quoted(tiny) + " -o " + shell_quoted((dir_ / "one").string()) +
                    " --quiet")
                .code,
            0);
  // A test that ran before in this process may have started MPI as a singleton, whose
  // environment (OMPI_*, PMIX_*) would make this mpirun believe it runs inside a job.
  const std::string clean_environment =
      "for v in $(env | sed -n 's/^\\(OMPI_[^=]*\\|PMIX_[^=]*\\|OPAL_[^=]*\\)=.*/\\1/p'); do "
      "unset $v; done; ";
  const std::string command = clean_environment +
                              "mpirun -np 2 --allow-run-as-root --oversubscribe " +
                              shell_quoted(SANGUIS_BINARY) + " run " + shell_quoted(tiny) + " -o " +
                              shell_quoted((dir_ / "two").string()) + " --quiet >" +
                              shell_quoted((dir_ / "mpirun.txt").string()) + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << read_text_file(dir_ / "mpirun.txt");

  // One block per process at each time in the index.
  const std::string pvd = read_text_file(dir_ / "two" / "particles.pvd");
  EXPECT_NE(pvd.find("part=\"1\" file=\"particles/particles_00000000_r1.vtu\""), std::string::npos);
  EXPECT_EQ(pvd.find("part=\"2\""), std::string::npos);

  for (const char* run : {"one", "two"}) {
    ASSERT_EQ(sanguis(std::string("analyze ") + shell_quoted((dir_ / run).string()) + " --out " +
                      shell_quoted((dir_ / (std::string(run) + "_analysis")).string()))
                  .code,
              0);
  }
  for (const char* table : {"summary.csv", "runout.csv", "height.csv", "velocity.csv",
                            "force_pdf.csv", "fabric.csv", "coordination.csv", "walls.csv"}) {
    EXPECT_EQ(read_text_file(dir_ / "one_analysis" / table),
              read_text_file(dir_ / "two_analysis" / table))
        << table;
  }
  // The run log says how the run was split.
  EXPECT_NE(read_text_file(dir_ / "two" / "run.log").find("2 MPI processes"), std::string::npos);
}

}  // namespace
}  // namespace sanguis
