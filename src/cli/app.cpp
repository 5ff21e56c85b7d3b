// cli/app.cpp — the tdpm command line (CLI11): `tdpm render`, global
// --help/--version, exit codes, the progress bar and the final summary.
// Flags are checked before any work, so a typo never costs a render.
#include "cli/app.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "cli/compare_command.h"
#include "cli/convert_command.h"
#include "cli/render_command.h"
#include "core/error.h"

namespace tdpm::cli {

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Prints help / version (exit 0) or the usage error; every usage error
    // exits 2, whatever CLI11's own code for it.
    int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  try {
    if (render->parsed()) return runRender(renderArgs);
    if (compare->parsed()) return runCompare(compareArgs);
    if (convert->parsed()) return runConvert(convertArgs);
  } catch (const Error& e) {
    std::fprintf(stderr, "tdpm: error: %s\n", e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "tdpm: error: out of memory\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tdpm: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}

}  // namespace tdpm::cli
