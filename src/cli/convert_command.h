// cli/convert_command.h — `tdpm convert SCENE.pbrt -o SCENE.json`: writes the
// tdpm scene (JSON, meshes as OBJ beside it) that the pbrt import makes of a
// pbrt-v3/v4 file; rendering either gives the same image.
// Exit codes: 0 written; 1 bad input (unsupported pbrt, unwritable output);
// 2 usage.
#pragma once
#include <CLI/CLI.hpp>
#include <string>

namespace tdpm::cli {

struct ConvertArgs {
  std::string input;
  std::string output;
  bool quiet = false;
};

CLI::App* addConvertCommand(CLI::App& app, ConvertArgs& args);
int runConvert(const ConvertArgs& args);

}  // namespace tdpm::cli
