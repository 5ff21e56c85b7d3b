// cli/app.h — the tdpm command line: subcommands, flags, exit codes.
#pragma once

namespace tdpm::cli {

// Parses arguments and runs a subcommand. Returns the process exit code:
// 0 success, 1 bad input or failure (message on stderr), 2 usage error.
int run(int argc, char** argv);

}  // namespace tdpm::cli
