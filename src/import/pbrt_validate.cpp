// import/pbrt_validate.cpp — one set of limits for both scene formats: the
// imported SceneDescription is written as tdpm JSON (in memory, meshes
// kept in memory too) and read back by scene::parseScene, so a .pbrt file
// renders only what its converted JSON would load. A refusal is reported
// at the pbrt statement that made the refused value (file:line), with the
// JSON key and the JSON side's own reason.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include "core/error.h"
#include "image/texture_image.h"
#include "import/pbrt_importer.h"
#include "scene/json_writer.h"
#include "scene/parse.h"

namespace tdpm::pbrt::detail {

namespace {

bool finite(Rgb c) { return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b); }

// "objects[12].motion[1].scale" -> 12 for prefix "objects["; -1 otherwise.
long indexAfter(const std::string& path, const std::string& prefix) {
  if (path.compare(0, prefix.size(), prefix) != 0) return -1;
  char* end = nullptr;
  long i = std::strtol(path.c_str() + prefix.size(), &end, 10);
  return end && *end == ']' ? i : -1;
}


}  // namespace

Loc Importer::locateJsonPath(const std::string& path) const {
  long i = indexAfter(path, "objects[");
  if (i >= 0 && size_t(i) < objectAt_.size()) return objectAt_[size_t(i)];
  i = indexAfter(path, "lights[");
  if (i >= 0 && size_t(i) < lightAt_.size()) return lightAt_[size_t(i)];
  auto given = [&](const Statement& s) { return s.given ? s.at : worldAt_; };
  if (path.compare(0, 10, "background") == 0 && !backgroundAt_.file.empty()) return backgroundAt_;
  if (path.compare(0, 17, "camera.resolution") == 0) return given(film_);
  if (path.compare(0, 6, "camera") == 0) return given(camera_);
  if (path.compare(0, 10, "render.spp") == 0) return given(sampler_);
  if (path.compare(0, 13, "render.filter") == 0) return given(pixelFilter_);
  if (path.compare(0, 6, "render") == 0) return given(integrator_);
  return worldAt_;
}

// Called by finish(), after every statement. Numbers the JSON cannot hold
// (an Inf power would be written as null) are refused here first.
void Importer::validateAsJson() {
  scene::SceneDescription& sc = result.scene;
  for (size_t i = 0; i < sc.lights.size(); ++i)
    if (!finite(sc.lights[i].power))
      failAt(lightAt_[i], sc.lights[i].name + ": its power is not a finite float (too bright after its scale factors)");
  if (!finite(sc.background)) failAt(backgroundAt_.file.empty() ? worldAt_ : backgroundAt_,
                                     "LightSource \"infinite\": the background radiance is not a finite float");

  // sceneToJson names mesh k "<stem>.mesh<k>.obj", objects' in order, then
  // mesh lights'. meshShape(d, k): mesh k of description d.
  const std::string stem = "imported";
  std::vector<std::pair<bool, size_t>> meshObject;  // (a light's, index)
  for (size_t i = 0; i < sc.objects.size(); ++i)
    if (sc.objects[i].shape.type == scene::ShapeDesc::Type::Mesh) meshObject.push_back({false, i});
  for (size_t i = 0; i < sc.lights.size(); ++i)
    if (sc.lights[i].type == scene::LightDesc::Type::Area && sc.lights[i].areaShape == scene::LightDesc::AreaShape::Mesh)
      meshObject.push_back({true, i});
  auto meshShape = [&](scene::SceneDescription& d, size_t k) -> scene::ShapeDesc& {
    return meshObject[k].first ? d.lights[meshObject[k].second].mesh : d.objects[meshObject[k].second].shape;
  };
  SceneJson js = sceneToJson(sc, stem + ".json", /*meshText=*/false);
  const std::string meshPrefix = stem + ".mesh";
  scene::MeshSource meshes = [&](const std::string& file, std::vector<Vec3f>* v, std::vector<uint32_t>* idx) {
    if (file.compare(0, meshPrefix.size(), meshPrefix) != 0) return false;
    size_t k = std::strtoul(file.c_str() + meshPrefix.size(), nullptr, 10);
    if (k >= meshObject.size()) return false;
    scene::ShapeDesc& s = meshShape(sc, k);
    v->swap(s.vertices);  // lent, not copied: given back below
    idx->swap(s.indices);
    return true;
  };
  // The images decoded already (texture files, environment maps), lent to
  // the parser by absolute path and key: read once per import.
  std::map<std::pair<std::string, std::string>, std::shared_ptr<const image::ImageRgb>> decoded;
  auto absolute = [](const std::string& f) { return std::filesystem::absolute(f).lexically_normal().string(); };
  for (const scene::TextureDef& t : sc.textures)
    if (t.image) decoded[{absolute(t.file), image::encodingName(t.encoding)}] = t.image;
  for (const scene::MaterialDesc& m : sc.materials)
    if (m.normalMap) decoded[{absolute(m.normalMapFile), "linear"}] = m.normalMap;
  for (const scene::LightDesc& l : sc.lights)
    if (l.map) decoded[{absolute(l.mapFile), l.equalArea ? "environment equal-area" : "environment latlong"}] = l.map;
  scene::ImageSource images = [&](const std::string& file, const std::string& key) -> std::shared_ptr<const image::ImageRgb> {
    auto it = decoded.find({absolute(file), key});
    return it == decoded.end() ? nullptr : it->second;
  };
  const std::string jsonName = "(imported scene)";
  scene::SceneDescription parsed;
  try {
    parsed = scene::parseScene(js.json, jsonName, meshes, images);
  } catch (const Error& e) {
    // "(imported scene):LINE: objects[3].motion[1].scale: problem"
    std::string what = e.what();
    std::string rest = what;
    if (what.compare(0, jsonName.size() + 1, jsonName + ":") == 0) {
      size_t colon = what.find(": ", jsonName.size() + 1);
      rest = colon == std::string::npos ? what : what.substr(colon + 2);
    }
    std::string path = rest.substr(0, rest.find(':'));
    Loc at = locateJsonPath(path);
    long i = indexAfter(path, "objects[");
    std::string label = i >= 0 && size_t(i) < sc.objects.size() ? sc.objects[size_t(i)].name
                        : (i = indexAfter(path, "lights[")) >= 0 && size_t(i) < sc.lights.size() ? sc.lights[size_t(i)].name
                                                                                                 : std::string("the scene");
    failAt(at, "tdpm's scene checks refuse what " + label + " maps to (the JSON of tdpm convert would not load): " + rest);
  }
  for (size_t k = 0; k < meshObject.size(); ++k) {
    scene::ShapeDesc& mine = meshShape(sc, k);
    scene::ShapeDesc& lent = meshShape(parsed, k);
    mine.vertices.swap(lent.vertices);
    mine.indices.swap(lent.indices);
  }
}

}  // namespace tdpm::pbrt::detail
