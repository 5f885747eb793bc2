#pragma once
// The processes of one job: an MPI world when glint was built with GLINT_WITH_MPI and started
// by mpirun, otherwise a single process. Collective calls must be made by every rank in the
// same order (MPI semantics); in a single process they return at once.
#include <cstdint>
#include <vector>

namespace glint {

class Distributed {
 public:
  // The job this process belongs to; initialises MPI on first use when the process was
  // started by an MPI launcher (and finalises it at exit).
  static Distributed& world();

  int rank() const { return rank_; }
  int size() const { return size_; }

  void barrier();
  // Element-wise reductions over all ranks, in place.
  void sum(std::vector<std::uint64_t>& values);
  void min(std::vector<std::int64_t>& values);
  void max(std::vector<std::int64_t>& values);
  void max(std::vector<double>& values);
  // Ends every rank of the job after a failure on this one (a lone exit would leave the
  // others waiting in a collective). In a single process: std::exit(code).
  [[noreturn]] void abort(int code);

 private:
  Distributed();
  int rank_ = 0;
  int size_ = 1;
};

// Number of processes the launcher started, from its environment (OMPI_COMM_WORLD_SIZE,
// PMI_SIZE, PMIX_SIZE); 1 when not started by one.
int launcher_world_size();

// Throws glint::Error when an MPI launcher started several copies of a glint built without
// MPI (each would run the whole job alone and write the same output).
void refuse_mpi_launch_without_mpi();

}  // namespace glint
