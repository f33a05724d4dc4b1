#include "flow/mpi_session.hpp"

#include <p4est_base.h>
#include <sc.h>

namespace sanguis::flow {

MpiSession& MpiSession::ensure() {
  static MpiSession session;  // process-wide by nature: MPI starts once per process
  return session;
}

MpiSession::MpiSession() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised == 0) {
    int provided = 0;
    // Threads (OpenMP over blocks) never call MPI: FUNNELED is enough.
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    owns_mpi_ = true;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  // No signal handlers, no backtraces, no log lines: the library reports
  // through exceptions, never through p4est's logging.
  sc_init(MPI_COMM_WORLD, 0, 0, nullptr, SC_LP_SILENT);
  p4est_init(nullptr, SC_LP_SILENT);
}

MpiSession::~MpiSession() {
  sc_finalize();
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (owns_mpi_ && finalised == 0) {
    MPI_Finalize();
  }
}

}  // namespace sanguis::flow
