// cli/convert_command.cpp — `tdpm convert`: pbrt import + JSON writer.
#include "cli/convert_command.h"

#include <cstdio>

#include "core/error.h"
#include "import/pbrt_import.h"
#include "scene/json_writer.h"

namespace tdpm::cli {

CLI::App* addConvertCommand(CLI::App& app, ConvertArgs& a) {
  CLI::App* c = app.add_subcommand(
      "convert", "Convert a pbrt-v3/v4 scene (the subset in docs/pbrt-import.md) to tdpm's JSON scene format");
  c->add_option("scene", a.input, "Input pbrt scene (.pbrt)")->required();
  c->add_option("-o,--output", a.output,
                "Output JSON scene (.json); triangle meshes are written beside it as <name>.mesh<i>.obj")
      ->required();
  c->add_flag("-q,--quiet", a.quiet, "Do not print the import's notes");
  return c;
}

int runConvert(const ConvertArgs& a) {
  if (!pbrt::isPbrtPath(a.input)) throw Error(a.input + ": convert reads pbrt scenes (.pbrt)");
  if (a.output.size() < 5 || a.output.compare(a.output.size() - 5, 5, ".json") != 0)
    throw Error("--output: '" + a.output + "' must end in .json");
  pbrt::ImportResult imported = pbrt::importPbrtFile(a.input);
  if (!a.quiet)
    for (const std::string& n : imported.notes) std::fprintf(stderr, "tdpm: note: %s\n", n.c_str());
  pbrt::writeSceneJson(imported.scene, a.output);
  if (!a.quiet)
    std::fprintf(stderr, "tdpm: %s -> %s (%zu objects, %zu lights, %zu materials)\n", a.input.c_str(), a.output.c_str(),
                 imported.scene.objects.size(), imported.scene.lights.size(), imported.scene.materials.size());
  return 0;
}

}  // namespace tdpm::cli
