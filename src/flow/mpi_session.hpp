#pragma once
// The process-wide MPI, sc and p4est start-up the flow solver needs.
//
// MPI can be initialised only once per process, so the session is one
// function-local object created on first use (the DEM paths never touch it and
// start without MPI). It works with and without mpirun (a singleton
// MPI_Init_thread), and finalises at program exit only what it initialised
// itself.

#include <mpi.h>

namespace sanguis::flow {

class MpiSession {
 public:
  /// The session, created (MPI, sc and p4est initialised) on first call.
  static MpiSession& ensure();

  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  ~MpiSession();

  [[nodiscard]] MPI_Comm world() const { return MPI_COMM_WORLD; }
  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }

 private:
  MpiSession();
  bool owns_mpi_ = false;  ///< true when this session called MPI_Init_thread
  int rank_ = 0;           ///< rank in MPI_COMM_WORLD
  int size_ = 1;           ///< number of ranks in MPI_COMM_WORLD
};

}  // namespace sanguis::flow
