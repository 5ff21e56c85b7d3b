// cli/main.cpp — program entry point; all logic lives in cli/app.cpp.
// SIGINT/SIGTERM remove the temporaries of outputs being written and end
// the process by that signal (core/signals.h); installed here, not in
// run(), so in-process tests keep the default behaviour.
#include "cli/app.h"
#include "core/signals.h"

int main(int argc, char** argv) {
  tdpm::signals::install(tdpm::signals::Mode::Exit);
  return tdpm::cli::run(argc, argv);
}
