#include "core/distributed.h"

#include <cstdlib>
#include <string>

#include "core/error.h"

#ifdef GLINT_WITH_MPI
#include <mpi.h>
#endif

namespace glint {
namespace {

int environment_size(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::atoi(value) : 0;
}

}  // namespace

int launcher_world_size() {
  int size = 1;
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    size = std::max(size, environment_size(name));
  }
  return size;
}

#ifdef GLINT_WITH_MPI

Distributed::Distributed() {
  // MPI only when a launcher started us: a plain `glint` run needs none of its start-up.
  if (launcher_world_size() <= 1 && std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr) return;
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    std::atexit([] {
      int finalised = 0;
      MPI_Finalized(&finalised);
      if (!finalised) MPI_Finalize();
    });
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

void Distributed::barrier() {
  if (size_ > 1) MPI_Barrier(MPI_COMM_WORLD);
}
void Distributed::sum(std::vector<std::uint64_t>& values) {
  if (size_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_UINT64_T,
                  MPI_SUM, MPI_COMM_WORLD);
  }
}
void Distributed::min(std::vector<std::int64_t>& values) {
  if (size_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T,
                  MPI_MIN, MPI_COMM_WORLD);
  }
}
void Distributed::max(std::vector<std::int64_t>& values) {
  if (size_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T,
                  MPI_MAX, MPI_COMM_WORLD);
  }
}
void Distributed::max(std::vector<double>& values) {
  if (size_ > 1) {
    MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX,
                  MPI_COMM_WORLD);
  }
}
void Distributed::abort(int code) {
  if (size_ > 1) MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

void refuse_mpi_launch_without_mpi() {}

#else

Distributed::Distributed() = default;
void Distributed::barrier() {}
void Distributed::sum(std::vector<std::uint64_t>&) {}
void Distributed::min(std::vector<std::int64_t>&) {}
void Distributed::max(std::vector<std::int64_t>&) {}
void Distributed::max(std::vector<double>&) {}
void Distributed::abort(int code) { std::exit(code); }

void refuse_mpi_launch_without_mpi() {
  const int size = launcher_world_size();
  if (size > 1) {
    throw Error("mpirun", "",
                "started " + std::to_string(size) +
                    " copies of a glint built without MPI; each would do the whole job alone. "
                    "Run it once without mpirun, or build with -DGLINT_WITH_MPI=ON");
  }
}

#endif

Distributed& Distributed::world() {
  static Distributed instance;
  return instance;
}

}  // namespace glint
