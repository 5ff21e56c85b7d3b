// cli/app.cpp — the tdpm command line (CLI11): `tdpm render`, global
// --help/--version, exit codes, the progress bar and the final summary.
// Flags are checked before any work, so a typo never costs a render.
#include "cli/app.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "cli/compare_command.h"
#include "cli/convert_command.h"
#include "cli/render_command.h"
#include "core/error.h"
#include "distributed/comm.h"

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

// Under mpirun the ranks may have been given other arguments (MPMD,
// `mpirun -np 1 tdpm A : -np 1 tdpm B`): a rank that stopped at its usage
// error alone, or ran another subcommand, left the others waiting for it
// for ever (issue 27 item 1). The ranks agree first, in one fixed-size
// allgather: when any of them stopped (`code` >= 0, with its help or error
// text in `out` / `err`), rank 0 prints the lowest such rank's text (named
// when it is not rank 0) and every rank returns that code; when their
// subcommands differ, every rank returns 2. Otherwise -1: go on.
int agreeOnArguments(dist::Comm& comm, int code, const std::string& out, const std::string& err, int subcommand) {
  std::vector<uint64_t> all = comm.allgather((code < 0 ? 0 : uint64_t(code) + 1) | (uint64_t(subcommand) << 8));
  int first = -1;
  for (size_t r = 0; r < all.size() && first < 0; ++r)
    if (all[r] & 0xff) first = int(r);
  if (first >= 0) {
    std::string text = comm.rank() == first ? out + '\0' + err : std::string();
    uint64_t n = text.size();
    comm.broadcast(&n, sizeof n, first);
    text.resize(size_t(n));
    if (n > 0) comm.broadcast(&text[0], n, first);
    if (comm.root()) {
      size_t cut = text.find('\0');
      std::string o = text.substr(0, cut), e = cut == std::string::npos ? std::string() : text.substr(cut + 1);
      std::string who = first != 0 ? "tdpm: rank " + std::to_string(first) + ": " : std::string();
      if (!o.empty()) std::fprintf(stdout, "%s%s", who.c_str(), o.c_str());
      if (!e.empty()) std::fprintf(stderr, "%s%s", who.c_str(), e.c_str());
      std::fflush(stdout);
    }
    return int((all[size_t(first)] & 0xff) - 1);
  }
  for (size_t r = 1; r < all.size(); ++r) {
    if (all[r] == all[0]) continue;
    static const char* const kNames[] = {"none", "render", "compare", "convert"};
    if (comm.root())
      std::fprintf(stderr, "tdpm: error: the ranks of this mpirun job run different subcommands: %s on rank 0, %s on rank %zu\n",
                   kNames[std::min<uint64_t>(3, all[0] >> 8)], kNames[std::min<uint64_t>(3, all[r] >> 8)], r);
    return 2;
  }
  return -1;
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
  // Help / version (exit 0) or the usage error (every usage error exits 2,
  // whatever CLI11's own code for it), printed into `out` / `err` first.
  std::ostringstream out, err;
  int code = -1;  // parsed
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    code = app.exit(e, out, err) == 0 ? 0 : 2;
  }
  if (comm.distributed()) {
    int agreed = agreeOnArguments(comm, code, out.str(), err.str(),
                                  render->parsed() ? 1 : compare->parsed() ? 2 : convert->parsed() ? 3 : 0);
    if (agreed >= 0) return agreed;
  } else if (code >= 0) {
    std::fputs(out.str().c_str(), stdout);
    std::fputs(err.str().c_str(), stderr);
    return code;
  }

  if (render->parsed()) return runReporting([&] { return runRender(renderArgs); }, comm, true);
  // compare and convert are not distributed: under mpirun rank 0 runs them
  // and every rank exits with its status.
  auto other = [&] {
    if (compare->parsed()) return runCompare(compareArgs);
    if (convert->parsed()) return runConvert(convertArgs);
    return 0;
  };
  int status = comm.root() ? runReporting(other, comm, false) : 0;
  return comm.distributed() ? comm.broadcastInt(status) : status;
}

}  // namespace tdpm::cli
