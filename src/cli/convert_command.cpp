// cli/convert_command.cpp — `tdpm convert`: pbrt import + JSON writer, with
// every output checked before anything is written.
#include "cli/convert_command.h"

#include <cstdio>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/atomic_file.h"

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

// Every output is checked before anything is written: none may be one of
// the files the import read (by identity, st_dev/st_ino, so a link or
// another spelling of the same file is caught too: a PLY named
// out.mesh1.obj, -o inc.json where the scene includes inc.json), and each
// must be writable (AtomicFile's checks: a directory in the way, a missing
// directory). Meshes are committed first, the JSON last, so a JSON never
// names meshes that are not there.
static void writeChecked(const pbrt::SceneJson& js, const std::string& jsonPath, const std::vector<std::string>& inputs) {
  std::vector<std::pair<std::string, const std::string*>> outputs;
  for (const auto& [path, text] : js.meshFiles) outputs.push_back({path, &text});
  outputs.push_back({jsonPath, &js.json});
  std::set<std::string> seen(inputs.begin(), inputs.end());
  for (const auto& o : outputs)
    for (const std::string& in : seen)
      if (sameFile(o.first, in))
        throw Error("--output: writing '" + o.first + "' would overwrite '" + in +
                    "', which the scene reads; choose another output name");
  std::vector<std::unique_ptr<AtomicFile>> files;
  for (const auto& o : outputs) files.push_back(std::make_unique<AtomicFile>(o.first));  // checks, writes nothing yet
  for (size_t i = 0; i < outputs.size(); ++i) writeTextToTemp(*files[i], *outputs[i].second);
  for (auto& f : files) f->commit();
}

int runConvert(const ConvertArgs& a) {
  if (!pbrt::isPbrtPath(a.input)) throw Error(a.input + ": convert reads pbrt scenes (.pbrt)");
  if (a.output.size() < 5 || a.output.compare(a.output.size() - 5, 5, ".json") != 0)
    throw Error("--output: '" + a.output + "' must end in .json");
  pbrt::ImportResult imported = pbrt::importPbrtFile(a.input);
  if (!a.quiet)
    for (const std::string& n : imported.notes) std::fprintf(stderr, "tdpm: note: %s\n", n.c_str());
  writeChecked(pbrt::sceneToJson(imported.scene, a.output), a.output, imported.inputFiles);
  if (!a.quiet)
    std::fprintf(stderr, "tdpm: %s -> %s (%zu objects, %zu lights, %zu materials)\n", a.input.c_str(), a.output.c_str(),
                 imported.scene.objects.size(), imported.scene.lights.size(), imported.scene.materials.size());
  return 0;
}

}  // namespace tdpm::cli
