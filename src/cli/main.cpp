// cli/main.cpp — program entry point; all logic lives in cli/app.cpp.
#include "cli/app.h"

int main(int argc, char** argv) { return tdpm::cli::run(argc, argv); }
