// cli/main.cpp — program entry point; all logic lives in cli/app.cpp.
// SIGINT/SIGTERM remove the temporaries of outputs being written and end
// the process by that signal (core/signals.h); installed here, not in
// run(), so in-process tests keep the default behaviour.
#include "cli/app.h"
#include "core/signals.h"
#include "distributed/comm.h"

int main(int argc, char** argv) {
  tdpm::signals::install(tdpm::signals::Mode::Exit);
  // MPI starts only when mpirun launched this process (distributed/comm.h): a
  // plain run never needs a launcher.
  tdpm::dist::Session mpi(argc, argv);
  if (!mpi.ok()) return 1;
  return tdpm::cli::run(argc, argv);
}
