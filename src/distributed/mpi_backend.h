// distributed/mpi_backend.h — what distributed/comm.cpp needs from distributed/mpi_comm.cpp, the
// one file that includes mpi.h (compiled only when TDPM_MPI is on).
#pragma once

namespace tdpm::dist {

class Comm;

namespace mpi {
// MPI_Init (MPI_THREAD_SERIALIZED: collectives on the thread that runs
// main; TBB workers only take tiles from a SharedCounter, behind its mutex). Returns the world Comm, alive until stop().
Comm* start(int& argc, char**& argv);
void stop();
}  // namespace mpi

}  // namespace tdpm::dist
