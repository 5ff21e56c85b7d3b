// scene/json_writer.cpp — writing a SceneDescription as JSON + OBJ.
#include "scene/json_writer.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"

namespace tdpm::pbrt {

namespace {

using Json = nlohmann::ordered_json;

// Exactly as scene/parse.cpp normalises a direction or a rotation axis
// (its safeNormalize: in double, then rounded to float). It used to divide
// by the largest component in float first; this copy still did, so a spot
// light's direction came back from the JSON up to 1 ulp off (issue 23).
Vec3f parserNormalize(Vec3f v) {
  double x = v.x, y = v.y, z = v.z, len = std::sqrt(x * x + y * y + z * z);
  return {float(x / len), float(y / len), float(z / len)};
}

// The shortest decimal that reads back as the same float (so the JSON shows
// 0.2, not 0.20000000298023224).
double num(float f) {
  char buf[32];
  for (int digits = 6; digits < 9; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(f));
    double d = std::strtod(buf, nullptr);
    if (float(d) == f) return d;
  }
  std::snprintf(buf, sizeof buf, "%.9g", double(f));
  return std::strtod(buf, nullptr);
}

Json vec(Vec3f v) { return Json::array({num(v.x), num(v.y), num(v.z)}); }
Json rgb(Rgb c) { return Json::array({num(c.r), num(c.g), num(c.b)}); }

bool isIdentity(const Quaternion& q) { return q.w == 1 && q.x == 0 && q.y == 0 && q.z == 0; }

Json rotation(const Quaternion& q) {
  Vec3f axis;
  float deg;
  axisAngleOf(q, &axis, &deg);
  return Json{{"axis", vec(axis)}, {"angle", num(deg)}};
}

Json transform(const scene::TransformDesc& t) {
  Json j = Json::object();
  if (t.translate.x != 0 || t.translate.y != 0 || t.translate.z != 0) j["translate"] = vec(t.translate);
  if (!isIdentity(t.rotate)) j["rotate"] = rotation(t.rotate);
  if (t.scale.x != 1 || t.scale.y != 1 || t.scale.z != 1) j["scale"] = vec(t.scale);
  return j;
}

Json motion(const scene::MotionDesc& m) {
  Json a = Json::array();
  for (size_t i = 0; i < m.times.size(); ++i) {
    Json k = transform(m.poses[i]);
    Json key = Json{{"time", num(m.times[i])}};
    for (auto& [name, value] : k.items()) key[name] = value;
    a.push_back(key);
  }
  return a;
}

Json texture(const scene::TextureDesc& t) {
  if (t.kind == scene::TextureDesc::Kind::Constant) return Json{{"type", "constant"}, {"color", rgb(t.color)}};
  return Json{{"type", "checker"}, {"colors", Json::array({rgb(t.color), rgb(t.color2)})}, {"scale", num(t.scale)}};
}

// A texture file's name as the JSON gives it: relative to the JSON's
// folder when both paths allow it, else absolute.
std::string relativeToJson(const std::string& file, const std::filesystem::path& jsonPath) {
  std::filesystem::path f = std::filesystem::absolute(file).lexically_normal();
  std::filesystem::path dir = std::filesystem::absolute(jsonPath).lexically_normal().parent_path();
  std::filesystem::path rel = f.lexically_relative(dir);
  return rel.empty() ? f.string() : rel.string();
}

// Every texture's name in the JSON: its own, made unique and non-empty.
std::vector<std::string> textureNames(const std::vector<scene::TextureDef>& defs) {
  std::vector<std::string> names;
  std::set<std::string> used;
  for (size_t i = 0; i < defs.size(); ++i) {
    std::string base = defs[i].name.empty() ? "texture" + std::to_string(i) : defs[i].name, name = base;
    for (int k = 2; used.count(name); ++k) name = base + "#" + std::to_string(k);
    used.insert(name);
    names.push_back(name);
  }
  return names;
}

Json texInput(const scene::TexInput& in, bool isFloat, const std::vector<std::string>& names) {
  if (in.texture >= 0) return names.at(size_t(in.texture));
  return isFloat ? Json(num(in.value.r)) : rgb(in.value);
}

Json namedTexture(const scene::TextureDef& t, const std::vector<scene::TextureDef>& defs,
                  const std::vector<std::string>& names, const std::filesystem::path& jp) {
  using K = scene::TextureDef::Kind;
  Json j;
  auto uv = [&]() {
    j["uscale"] = num(t.uscale);
    j["vscale"] = num(t.vscale);
    j["udelta"] = num(t.udelta);
    j["vdelta"] = num(t.vdelta);
  };
  switch (t.kind) {
    case K::Constant: j["type"] = "constant"; j["value"] = texInput(t.a, t.isFloat, names); break;
    case K::Image:
      j["type"] = "image";
      j["file"] = relativeToJson(t.file, jp);
      j["encoding"] = image::encodingName(t.encoding);
      j["wrap"] = t.wrap == scene::TextureDef::Wrap::Repeat ? "repeat" : t.wrap == scene::TextureDef::Wrap::Clamp ? "clamp" : "black";
      j["filter"] = t.filter == scene::TextureDef::Filter::Bilinear ? "bilinear" : "point";
      j["scale"] = num(t.scale);
      j["invert"] = t.invert;
      uv();
      break;
    case K::Scale:
      j["type"] = "scale";
      j["texture"] = texInput(t.a, t.isFloat, names);
      // A spectrum texture's scale may be RGB (pbrt-v3's tex1 x tex2): written as one then.
      j["scale"] = texInput(t.b, t.isFloat || (t.b.texture >= 0 ? defs.at(size_t(t.b.texture)).isFloat
                                                                 : t.b.value.r == t.b.value.g && t.b.value.g == t.b.value.b),
                            names);
      break;
    case K::Mix:
      j["type"] = "mix";
      j["tex1"] = texInput(t.a, t.isFloat, names);
      j["tex2"] = texInput(t.b, t.isFloat, names);
      j["amount"] = texInput(t.amount, true, names);
      break;
    case K::Checkerboard:
    case K::Checker3D:
      j["type"] = t.kind == K::Checkerboard ? "checkerboard" : "checker3d";
      j["tex1"] = texInput(t.a, t.isFloat, names);
      j["tex2"] = texInput(t.b, t.isFloat, names);
      if (t.kind == K::Checkerboard) uv();
      else j["scale"] = num(t.cell);
      break;
  }
  if (t.isFloat) j["float"] = true;
  return j;
}

Json material(const scene::MaterialDesc& m, const std::vector<scene::MaterialDesc>& materials,
              const std::vector<std::string>& textures, const std::filesystem::path& jp) {
  using T = scene::MaterialDesc::Type;
  Json j;
  auto albedo = [&]() {
    if (m.albedoTexture >= 0) j["texture"] = textures.at(size_t(m.albedoTexture));
    else if (m.albedo.kind == scene::TextureDesc::Kind::Constant) j["color"] = rgb(m.albedo.color);
    else j["texture"] = texture(m.albedo);
  };
  Json spec = m.specularTexture >= 0 ? Json(textures.at(size_t(m.specularTexture))) : rgb(m.specular);
  // A textured roughness: the texture's name and its remap (parse.cpp).
  using R = scene::MaterialDesc::Remap;
  if ((m.roughnessTexture >= 0 || m.baseRoughnessTexture >= 0) && m.roughnessRemap != R::None)
    j["roughness_remap"] = m.roughnessRemap == R::PbrtV3 ? "pbrt-v3" : "pbrt-v4";
  Json iorValue = m.iorTexture >= 0 ? Json(textures.at(size_t(m.iorTexture))) : Json(num(m.ior));
  auto rough = [&]() -> Json { return m.roughnessTexture < 0 ? Json(num(m.roughness)) : Json(textures.at(size_t(m.roughnessTexture))); };
  // A conductor's complex IOR: a textured reflectance (eta, k per hit), or
  // eta and k, each constant or a texture's name.
  auto complexIor = [&]() {
    if (m.specularTexture >= 0) {
      j["color"] = spec;
      return;
    }
    j["eta"] = m.etaTexture >= 0 ? Json(textures.at(size_t(m.etaTexture))) : rgb(m.eta);
    j["k"] = m.kTexture >= 0 ? Json(textures.at(size_t(m.kTexture))) : rgb(m.k);
  };
  Json thickness = m.thicknessTexture >= 0 ? Json(textures.at(size_t(m.thicknessTexture))) : Json(num(m.thickness));
  switch (m.type) {
    case T::Diffuse:
      j["type"] = "diffuse";
      albedo();
      if (m.sigmaTexture >= 0) j["sigma"] = textures.at(size_t(m.sigmaTexture));
      else if (m.sigma != 0.0f) j["sigma"] = num(m.sigma);
      break;
    case T::Interface: j["type"] = "interface"; break;
    case T::Mirror: j["type"] = "mirror"; j["color"] = spec; break;
    case T::Dielectric: j["type"] = "dielectric"; j["ior"] = iorValue; j["tint"] = spec; break;
    case T::Metal: j["type"] = "metal"; j["color"] = spec; j["roughness"] = rough(); break;
    case T::Plastic:
      j["type"] = "plastic";
      albedo();
      j["ior"] = num(m.ior);
      j["roughness"] = rough();
      break;
    case T::Conductor:
      j["type"] = "conductor";
      complexIor();
      j["roughness"] = rough();
      break;
    case T::RoughDielectric:
      j["type"] = "dielectric";
      j["ior"] = iorValue;
      j["tint"] = spec;
      j["roughness"] = rough();
      break;
    case T::Uber:
    case T::Substrate:
      j["type"] = m.type == T::Uber ? "uber" : "substrate";
      albedo();
      j["specular"] = spec;
      if (m.type == T::Uber) j["ior"] = iorValue;
      j["roughness"] = rough();
      break;
    case T::CoatedDiffuse:
      j["type"] = "coateddiffuse";
      albedo();
      j["ior"] = num(m.ior);
      j["roughness"] = rough();
      j["thickness"] = thickness;
      break;
    case T::CoatedConductor:
      j["type"] = "coatedconductor";
      j["ior"] = num(m.ior);
      j["roughness"] = rough();
      complexIor();
      j["conductor_roughness"] =
          m.baseRoughnessTexture < 0 ? Json(num(m.baseRoughness)) : Json(textures.at(size_t(m.baseRoughnessTexture)));
      j["thickness"] = thickness;
      break;
    case T::Mix:
      j["type"] = "mix";
      j["materials"] = Json::array({materials.at(m.mix[0]).name, materials.at(m.mix[1]).name});
      if (m.amountTexture >= 0) j["amount"] = textures.at(size_t(m.amountTexture));  // a spectrum one: per channel
      else j["amount"] = m.amountPerChannel ? rgb(m.amountRgb) : Json(num(m.amount));
      break;
  }
  // Shading normals (parse.cpp readShadingNormal).
  if (m.bumpTexture >= 0) {
    if (m.bumpScale == 1.0f) j["bump"] = textures.at(size_t(m.bumpTexture));
    else j["bump"] = Json{{"texture", textures.at(size_t(m.bumpTexture))}, {"scale", num(m.bumpScale)}};
  }
  if (!m.normalMapFile.empty()) j["normal_map"] = relativeToJson(m.normalMapFile, jp);
  return j;
}

// Shortest text that reads back as the same float (OBJ readers parse to
// double, then round to float: 9 significant digits are enough).
std::string objNumber(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

std::string objText(const scene::ShapeDesc& s) {
  std::string out = "# written by tdpm convert\n";
  for (Vec3f v : s.vertices) out += "v " + objNumber(v.x) + " " + objNumber(v.y) + " " + objNumber(v.z) + "\n";
  const bool uv = s.uvs.size() == s.indices.size();
  if (uv)
    for (Vec2f t : s.uvs) out += "vt " + objNumber(t.x) + " " + objNumber(t.y) + "\n";
  const bool normals = s.normals.size() == s.indices.size();
  if (normals)
    for (Vec3f n : s.normals) out += "vn " + objNumber(n.x) + " " + objNumber(n.y) + " " + objNumber(n.z) + "\n";
  // With uv, corner k of the file's faces is vt k + 1 (one vt per corner);
  // with normals, vn k + 1 likewise.
  auto corner = [&](size_t k) {
    std::string c = std::to_string(s.indices[k] + 1);
    if (uv || normals) c += "/" + (uv ? std::to_string(k + 1) : std::string());
    if (normals) c += "/" + std::to_string(k + 1);
    return c;
  };
  for (size_t i = 0; i + 2 < s.indices.size(); i += 3) out += "f " + corner(i) + " " + corner(i + 1) + " " + corner(i + 2) + "\n";
  return out;
}

// ---- participating media (media-format.md: the keys M1's parser reads)

// A medium reference: its name, or null for vacuum.
Json mediumRef(const scene::SceneDescription& sc, int32_t i) {
  if (i < 0) return nullptr;
  return sc.media.at(size_t(i)).name;
}

Json medium(const scene::MediumDesc& m, const std::filesystem::path& jp) {
  Json j;
  bool grid = m.type == scene::MediumDesc::Type::Grid;
  j["type"] = grid ? "grid" : "homogeneous";
  j["sigma_a"] = rgb(m.sigmaA);
  j["sigma_s"] = rgb(m.sigmaS);
  j["scale"] = num(m.scale);
  j["g"] = num(m.g);
  if (!grid) return j;
  const scene::DensityGridDesc& g = m.grid;
  if (!g.file.empty()) {
    // By reference: the parser reads the file again (grid_file.h).
    j["file"] = relativeToJson(g.file, jp);
    j["grid"] = g.gridName;
  } else {
    j["resolution"] = Json::array({g.nx, g.ny, g.nz});
    Json d = Json::array();
    for (float v : g.density) d.push_back(num(v));
    j["density"] = d;
  }
  // Always written: for a file these are the grid's own world bounds, which
  // the parser would compute, so the written value is the same.
  j["bounds"] = Json::array({vec(g.bounds.lo), vec(g.bounds.hi)});
  Json t = transform(m.placement);
  if (!t.empty()) j["transform"] = t;
  return j;
}

// "medium" of the camera and of a light: written when it differs from the
// JSON's default (the exterior medium); null is vacuum.
void defaultedMedium(Json& j, const scene::SceneDescription& sc, int32_t i) {
  if (i != sc.exteriorMedium) j["medium"] = mediumRef(sc, i);
}

const char* lightType(const scene::LightDesc& l) {
  if (l.type == scene::LightDesc::Type::Area) {
    switch (l.areaShape) {
      case scene::LightDesc::AreaShape::Rect: return "area";
      case scene::LightDesc::AreaShape::Sphere: return "sphere";
      case scene::LightDesc::AreaShape::Disk: return "disk";
      case scene::LightDesc::AreaShape::Mesh: return "mesh";
    }
  }
  switch (l.type) {
    case scene::LightDesc::Type::Point: return "point";
    case scene::LightDesc::Type::Spot: return "spot";
    case scene::LightDesc::Type::Directional: return "directional";
    case scene::LightDesc::Type::Area: return "area";
    case scene::LightDesc::Type::Environment: return "environment";
  }
  return "point";
}

}  // namespace

Quaternion rotationAsParsed(Vec3f axis, float degrees) {
  constexpr float kDegrees = kPi / 180.0f;
  return Quaternion::fromAxisAngle(parserNormalize(axis), degrees * kDegrees);
}

void axisAngleOf(const Quaternion& q, Vec3f* axis, float* degrees) {
  // No sign normalisation (w < 0 gives an angle above 180 degrees): q and
  // -q are the same rotation, but only q itself reads back bit for bit.
  double s = std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z);
  if (s == 0) {
    *axis = {0, 1, 0};
    *degrees = 0;
    return;
  }
  *axis = {float(q.x / s), float(q.y / s), float(q.z / s)};
  *degrees = float(2.0 * std::atan2(s, double(q.w)) * 180.0 / 3.14159265358979323846);
}

Quaternion canonicalRotation(const Quaternion& q) {
  Quaternion c = q;
  for (int i = 0; i < 4; ++i) {
    Vec3f axis;
    float deg;
    axisAngleOf(c, &axis, &deg);
    if (deg == 0) return Quaternion{};
    Quaternion next = rotationAsParsed(axis, deg);
    if (next.w == c.w && next.x == c.x && next.y == c.y && next.z == c.z) return c;
    c = next;
  }
  return c;
}

Vec3f canonicalDirection(Vec3f d) {
  for (int i = 0; i < 4; ++i) {
    Vec3f n = parserNormalize(d);
    if (n.x == d.x && n.y == d.y && n.z == d.z) return d;
    d = n;
  }
  return d;
}

SceneJson sceneToJson(const scene::SceneDescription& sc, const std::string& jsonPath, bool meshText) {
  SceneJson out;
  std::filesystem::path jp(jsonPath);
  std::string stem = jp.stem().string();
  Json root;
  const scene::CameraDesc& c = sc.camera;
  Json cam{{"position", vec(c.position)}, {"target", vec(c.target)}, {"up", vec(c.up)}, {"fov", num(c.fovDegrees)},
           {"resolution", Json::array({c.width, c.height})},
           {"shutter", Json::array({num(c.shutterOpen), num(c.shutterClose)})}};
  if (!c.motion.empty()) {
    Json m = Json::array();
    for (const auto& k : c.motion)
      m.push_back(Json{{"time", num(k.time)}, {"position", vec(k.position)}, {"target", vec(k.target)}, {"up", vec(k.up)}});
    cam["motion"] = m;
  }
  if (c.lensRadius > 0) {
    cam["lens_radius"] = num(c.lensRadius);
    cam["focal_distance"] = num(c.focalDistance);
  }
  defaultedMedium(cam, sc, c.medium);
  root["camera"] = cam;
  if (!sc.media.empty()) {
    Json media = Json::object();
    for (const auto& m : sc.media) {
      if (m.name.empty() || media.contains(m.name)) throw Error(jsonPath + ": two media are named \"" + m.name + "\" (or one has no name)");
      media[m.name] = medium(m, jp);
    }
    root["media"] = media;
  }
  if (sc.exteriorMedium >= 0) root["exterior_medium"] = mediumRef(sc, sc.exteriorMedium);
  std::vector<std::string> texNames = textureNames(sc.textures);
  if (!sc.textures.empty()) {
    Json textures = Json::object();
    for (size_t i = 0; i < sc.textures.size(); ++i) textures[texNames[i]] = namedTexture(sc.textures[i], sc.textures, texNames, jp);
    root["textures"] = textures;
  }
  Json materials = Json::object();
  for (const auto& m : sc.materials) {
    if (materials.contains(m.name)) throw Error(jsonPath + ": two materials are named \"" + m.name + "\"");
    materials[m.name] = material(m, sc.materials, texNames, jp);
  }
  root["materials"] = materials;
  Json objects = Json::array();
  for (const auto& o : sc.objects) {
    Json j{{"name", o.name}};
    const scene::ShapeDesc& s = o.shape;
    switch (s.type) {
      case scene::ShapeDesc::Type::Sphere: j["shape"] = Json{{"type", "sphere"}, {"radius", num(s.radius)}}; break;
      case scene::ShapeDesc::Type::Quad:
        j["shape"] = Json{{"type", "quad"}, {"size", Json::array({num(s.size.x), num(s.size.z)})}};
        break;
      case scene::ShapeDesc::Type::Box: j["shape"] = Json{{"type", "box"}, {"size", vec(s.size)}}; break;
      case scene::ShapeDesc::Type::Mesh: {
        std::string name = stem + ".mesh" + std::to_string(out.meshFiles.size()) + ".obj";
        out.meshFiles.push_back({(jp.parent_path() / name).string(), meshText ? objText(s) : std::string()});
        j["shape"] = Json{{"type", "mesh"}, {"file", name}};
        // The control mesh and its levels: the reader refines exactly as the import did.
        if (s.loopLevels >= 0) j["shape"]["subdivision"] = Json{{"scheme", "loop"}, {"levels", s.loopLevels}};
        break;
      }
      case scene::ShapeDesc::Type::Disk:
        j["shape"] = Json{{"type", "disk"}, {"radius", num(s.radius)}, {"inner_radius", num(s.innerRadius)},
                          {"height", num(s.height)}, {"phi_max", num(s.phiMax)}};
        break;
      case scene::ShapeDesc::Type::Cylinder:
        j["shape"] = Json{{"type", "cylinder"}, {"radius", num(s.radius)}, {"z_min", num(s.zMin)}, {"z_max", num(s.zMax)},
                          {"phi_max", num(s.phiMax)}};
        break;
    }
    if (s.reverseOrientation) j["shape"]["reverse_orientation"] = true;
    j["material"] = sc.materials.at(o.material).name;
    Json t = transform(o.placement);
    if (!t.empty()) j["transform"] = t;
    if (!o.motion.empty()) j["motion"] = motion(o.motion);
    // The general form always (the "medium" sugar reads back to the same).
    if (o.media.present)
      j["medium_interface"] = Json{{"inside", mediumRef(sc, o.media.inside)}, {"outside", mediumRef(sc, o.media.outside)}};
    objects.push_back(j);
  }
  root["objects"] = objects;
  Json lights = Json::array();
  for (const auto& l : sc.lights) {
    Json j{{"type", lightType(l)}, {"name", l.name}};
    switch (l.type) {
      case scene::LightDesc::Type::Point: j["position"] = vec(l.position); j["power"] = rgb(l.power); break;
      case scene::LightDesc::Type::Spot:
        j["position"] = vec(l.position);
        j["direction"] = vec(l.direction);
        j["cone_angle"] = num(l.coneAngle);
        j["falloff_start"] = num(l.falloffStart);
        j["power"] = rgb(l.power);
        break;
      case scene::LightDesc::Type::Directional:
        j["direction"] = vec(l.direction);
        j["irradiance"] = rgb(l.power);
        break;
      case scene::LightDesc::Type::Area:
        switch (l.areaShape) {
          case scene::LightDesc::AreaShape::Rect: j["size"] = Json::array({num(l.areaSize.x), num(l.areaSize.y)}); break;
          case scene::LightDesc::AreaShape::Sphere:
          case scene::LightDesc::AreaShape::Disk: j["radius"] = num(l.radius); break;
          case scene::LightDesc::AreaShape::Mesh: {
            std::string name = stem + ".mesh" + std::to_string(out.meshFiles.size()) + ".obj";
            out.meshFiles.push_back({(jp.parent_path() / name).string(), meshText ? objText(l.mesh) : std::string()});
            j["file"] = name;
            if (l.mesh.loopLevels >= 0) j["subdivision"] = Json{{"scheme", "loop"}, {"levels", l.mesh.loopLevels}};
            break;
          }
        }
        if (l.twoSided) j["two_sided"] = true;
        if (l.reverseOrientation) j["reverse_orientation"] = true;
        j["power"] = rgb(l.power);
        break;
      case scene::LightDesc::Type::Environment:
        j["L"] = rgb(l.radiance);
        j["scale"] = num(l.scale);
        if (!l.mapFile.empty()) {
          // Relative to the written JSON when both paths allow it.
          std::filesystem::path map = std::filesystem::absolute(l.mapFile).lexically_normal();
          std::filesystem::path dir = std::filesystem::absolute(jp).lexically_normal().parent_path();
          std::filesystem::path rel = map.lexically_relative(dir);
          j["filename"] = rel.empty() ? map.string() : rel.string();
          if (l.equalArea) j["mapping"] = "equal-area";
        }
        break;
    }
    Json t = transform(l.placement);
    if (!t.empty()) j["transform"] = t;
    if (!l.motion.empty()) j["motion"] = motion(l.motion);
    defaultedMedium(j, sc, l.medium);
    lights.push_back(j);
  }
  root["lights"] = lights;
  root["background"] = rgb(sc.background);
  const scene::RenderSettings& r = sc.render;
  Json render = Json::object();
  if (r.method) render["method"] = *r.method;
  if (r.spp) render["spp"] = *r.spp;
  if (r.maxSpp) render["max_spp"] = *r.maxSpp;
  if (r.contrast) render["contrast"] = num(*r.contrast);
  if (r.seed) render["seed"] = *r.seed;
  if (r.maxDepth) render["max_depth"] = *r.maxDepth;
  if (r.directOnly) render["direct_only"] = *r.directOnly;
  if (r.exposure) render["exposure"] = num(*r.exposure);
  if (r.photons) render["photons"] = *r.photons;
  if (r.photonsPerPixel) render["photons_per_pixel"] = *r.photonsPerPixel;
  if (r.globalPhotons) render["global_photons"] = *r.globalPhotons;
  if (r.volumePhotons) render["volume_photons"] = *r.volumePhotons;
  if (r.frames) render["frames"] = *r.frames;
  if (r.search) render["search"] = *r.search;
  if (r.k) render["k"] = *r.k;
  if (r.fraction) render["fraction"] = num(*r.fraction);
  if (r.kappa) render["kappa"] = num(*r.kappa);
  if (r.maxRadius) render["max_radius"] = num(*r.maxRadius);
  if (r.maxDt) render["max_dt"] = num(*r.maxDt);
  if (r.kernelSpace) render["kernel_space"] = *r.kernelSpace;
  if (r.kernelTime) render["kernel_time"] = *r.kernelTime;
  if (r.gather) render["gather"] = *r.gather;
  if (r.sampler) render["sampler"] = *r.sampler;
  if (r.filter) render["filter"] = *r.filter;
  if (r.filterRadius) render["filter_radius"] = num(*r.filterRadius);
  if (r.progressive) render["progressive"] = *r.progressive;
  if (r.passes) render["passes"] = *r.passes;
  if (r.timeLimit) render["time_limit"] = num(*r.timeLimit);
  root["render"] = render;
  out.json = root.dump(2) + "\n";
  return out;
}

void writeSceneJson(const scene::SceneDescription& scene, const std::string& jsonPath) {
  SceneJson s = sceneToJson(scene, jsonPath);
  for (const auto& [path, text] : s.meshFiles) writeTextFileAtomic(path, text);
  writeTextFileAtomic(jsonPath, s.json);
}

}  // namespace tdpm::pbrt
