// cli/app.cpp — the tdpm command line (CLI11): `tdpm render`, global
// --help/--version, exit codes, the progress bar and the final summary.
// Flags are checked before any work, so a typo never costs a render.
#include "cli/app.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>

#include "cli/compare_command.h"
#include "cli/convert_command.h"
#include "cli/render_command.h"
#include "core/error.h"
#include "dist/comm.h"

namespace tdpm::cli {

namespace {

// Runs a subcommand and turns what it throws into a message and an exit
// status. Under mpirun (`everyRank`: all ranks run it), an error every rank
// agreed on (dist::AgreedError) is printed by rank 0 alone and every rank
// returns 1; an error of one rank alone ends the whole job (the others
// would wait for it forever), with the rank named.
template <class F>
int runReporting(F&& f, dist::Comm& comm, bool everyRank) {
  auto fail = [&](const std::string& text, int code) {
    if (everyRank && comm.distributed())
      comm.abort("tdpm: " + text + " (rank " + std::to_string(comm.rank()) + " of " + std::to_string(comm.size()) +
                     "; ending the job)",
                 code);
    std::fprintf(stderr, "tdpm: %s\n", text.c_str());
    return code;
  };
  try {
    return f();
  } catch (const dist::AgreedError& e) {
    if (comm.root()) std::fprintf(stderr, "tdpm: error: %s\n", e.what());
    return 1;
  } catch (const Error& e) {
    return fail(std::string("error: ") + e.what(), 1);
  } catch (const std::bad_alloc&) {
    return fail("error: out of memory", 1);
  } catch (const std::exception& e) {
    return fail(std::string("internal error: ") + e.what(), 3);
  }
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"tdpm: time-dependent photon mapping renderer for motion-blurred global illumination"};
  app.set_version_flag("--version", std::string("tdpm ") + TDPM_VERSION);
  app.require_subcommand(1);
  app.fallthrough(false);

  RenderArgs renderArgs;
  CLI::App* render = addRenderCommand(app, renderArgs);
  CompareArgs compareArgs;
  CLI::App* compare = addCompareCommand(app, compareArgs);
  ConvertArgs convertArgs;
  CLI::App* convert = addConvertCommand(app, convertArgs);

  dist::Comm& comm = dist::world();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Prints help / version (exit 0) or the usage error; every usage error
    // exits 2, whatever CLI11's own code for it. Under mpirun every rank
    // parses the same arguments; rank 0 alone prints.
    std::ostringstream quiet;
    int code = comm.root() ? app.exit(e) : app.exit(e, quiet, quiet);
    return code == 0 ? 0 : 2;
  }

  if (render->parsed()) return runReporting([&] { return runRender(renderArgs); }, comm, true);
  // compare and convert are not distributed: under mpirun rank 0 runs them
  // and every rank exits with its status.
  auto other = [&] {
    if (compare->parsed()) return runCompare(compareArgs);
    if (convert->parsed()) return runConvert(convertArgs);
    return 0;
  };
  int code = comm.root() ? runReporting(other, comm, false) : 0;
  return comm.distributed() ? comm.broadcastInt(code) : code;
}

}  // namespace tdpm::cli
