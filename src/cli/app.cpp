// cli/app.cpp — placeholder until the render subcommand lands.
#include "cli/app.h"

#include <cstdio>

namespace tdpm::cli {
int run(int, char**) {
  std::printf("tdpm %s\n", TDPM_VERSION);
  return 0;
}
}  // namespace tdpm::cli
