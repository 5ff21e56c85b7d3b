// import/pbrt_media.cpp — pbrt's participating media onto the scene
// description (issue 25): MakeNamedMedium (homogeneous, uniformgrid and
// pbrt-v3's heterogeneous, nanovdb; presets from pbrt's table of measured
// media), the media named by MediumInterface on shapes, area lights and
// lights, the camera's medium, and the no-surface "interface" material.
// Names are resolved once the whole file is read (pbrt-v4 allows a medium
// to be made after a MediumInterface names it). docs/pbrt-import.md,
// "Participating media", is the user-facing version.
#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "import/pbrt_importer.h"
#include "media/grid_file.h"
#include "scene/json_writer.h"

namespace tdpm::pbrt::detail {

namespace {

// pbrt's table of measured media (GetMediumScatteringProperties; the same
// numbers in pbrt-v3 and v4): sigma'_s (reduced scattering) and sigma_a,
// in mm^-1 as measured. pbrt uses them as they are, per scene unit, times
// "scale", and sigma'_s as sigma_s (with the medium's g, 0 by default): so
// does tdpm. Jensen, Marschner, Levoy and Hanrahan 2001 (the first twelve)
// and Narasimhan, Gupta, Donner, Ramamoorthi, Nayar and Jensen 2006.
struct Preset {
  const char* name;
  float sigmaPrimeS[3], sigmaA[3];
};
const Preset kPresets[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0, 0}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0, 0}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo", {0.023805f, 0.028804f, 0.034306f}, {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder", {0.00012103f, 0.00013073f, 0.00012528f}, {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water", {0.0001764f, 0.00032095f, 0.00019617f}, {0.031845f, 0.031324f, 0.030147f}},
};

const Preset* findPreset(const std::string& name) {
  for (const Preset& p : kPresets)
    if (name == p.name) return &p;
  return nullptr;
}

bool finiteNonNegative(Rgb c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b) && c.r >= 0 && c.g >= 0 && c.b >= 0;
}

// A grid density the JSON's limits also allow (4 GiB), and at most half the
// memory available when the import began (as the JSON parser sizes grids).
uint64_t gridByteBudget(uint64_t memoryAtStart) {
  uint64_t cap = uint64_t(4) << 30;
  return memoryAtStart > 0 ? std::min(cap, memoryAtStart / 2) : cap;
}

}  // namespace

// sigma_a, sigma_s, preset, scale, g. pbrt-v4: a preset replaces
// sigma_a / sigma_s (which are then unused), defaults 1 and 1. pbrt-v3: a
// preset gives the defaults that sigma_a / sigma_s override, and without
// one the defaults are pbrt-v3's whole milk (sigma_a .0011 .0024 .014,
// sigma_s 2.55 3.21 3.77). An unknown preset, which pbrt only warns
// about, is an error here.
void Importer::mediumCoefficients(scene::MediumDesc& m, const ParamSet& ps, const std::string& what, bool v3) {
  Rgb sa = v3 ? Rgb(0.0011f, 0.0024f, 0.014f) : Rgb(1.0f), ss = v3 ? Rgb(2.55f, 3.21f, 3.77f) : Rgb(1.0f);
  bool fromPreset = false;
  if (ps.has("preset")) {
    std::string name = ps.getString("preset", "");
    const Preset* p = findPreset(name);
    if (!p) ps.fail(*ps.find("preset"), "unknown preset \"" + name + "\" (pbrt's measured media: Apple, Chicken1, ..., Wholemilk, "
                                        "Lowfat Milk, ..., Pacific Ocean Surface Water; see docs/pbrt-import.md)");
    sa = Rgb(p->sigmaA[0], p->sigmaA[1], p->sigmaA[2]);
    ss = Rgb(p->sigmaPrimeS[0], p->sigmaPrimeS[1], p->sigmaPrimeS[2]);
    fromPreset = !v3;
  }
  if (fromPreset) {
    for (const char* q : {"sigma_a", "sigma_s"})
      if (ps.has(q)) {
        ps.markUsed(q);
        note(Loc{ps.file(), ps.find(q)->line}, what + ": \"" + q + "\" ignored: a preset replaces it (as pbrt-v4 does)");
      }
  } else {
    sa = color(ps, "sigma_a", sa);
    ss = color(ps, "sigma_s", ss);
  }
  auto check = [&](const char* name, Rgb c) {
    if (!finiteNonNegative(c)) {
      const Param* p = ps.find(name);
      if (p) ps.fail(*p, "must be finite and >= 0 in every channel");
      throw Error(ps.file() + ": " + what + ": " + name + " must be finite and >= 0");
    }
  };
  check("sigma_a", sa);
  check("sigma_s", ss);
  double scale = ps.getFloat("scale", 1), g = ps.getFloat("g", 0);
  if (!(std::isfinite(scale) && scale >= 0)) ps.fail(*ps.find("scale"), "must be finite and >= 0, got " + fmtNum(scale));
  if (!(g > -1 && g < 1)) ps.fail(*ps.find("g"), "the Henyey-Greenstein g must be in (-1, 1), got " + fmtNum(g));
  m.sigmaA = sa;
  m.sigmaS = ss;
  m.scale = float(scale);
  m.g = float(g);
  if (!finiteNonNegative(m.sigmaA * m.scale) || !finiteNonNegative(m.sigmaS * m.scale))
    ps.fail(*ps.find("scale"), "scale x sigma overflows a float");
}

// A grid's medium space is the CTM at MakeNamedMedium (pbrt's medium-to-
// world), with tdpm's x mirror; its start transform only, as pbrt-v4.
void Importer::mediumPlacement(scene::MediumDesc& m, const Loc& at, const std::string& what) {
  if (!(gs_.ctm[0] == gs_.ctm[1])) note(at, what + ": an animated transform; pbrt and tdpm use its start transform");
  Mat M = (mirror_ ? mirrorX() : Mat()) * gs_.ctm[0];
  std::string degenerate = scaleProblem(M);
  if (!degenerate.empty()) failAt(at, what + ": its transform is unusable: " + degenerate);
  std::optional<Pose> p = decompose(M);
  if (!p) failAt(at, what + ": a grid medium under shear or a scale along rotated axes is not supported (tdpm's placements are translate x rotate x scale)");
  m.placement.translate = p->translate;
  m.placement.rotate = canonicalRotation(p->rotate);
  m.placement.scale = p->scale;
}

void Importer::mediumGrid(scene::MediumDesc& m, const std::string& type, const ParamSet& ps, const Loc& at, const std::string& what) {
  m.type = scene::MediumDesc::Type::Grid;
  scene::DensityGridDesc& g = m.grid;
  if (type == "nanovdb") {
    std::string file = ps.getString("filename", "");
    if (file.empty()) failAt(at, what + ": missing parameter \"string filename\"");
    g.file = resolvePath(file, at.file, mainDir);
    g.gridName = "density";
    media::loadDensityGridFile(g, at.str() + ": " + what, gridByteBudget(memoryAtStart_));
    result.inputFiles.push_back(g.file);
    // pbrt-v4 makes a "temperature" grid in the same file a blackbody
    // emitter (scaled by Lescale): refused, not silently left out.
    scene::DensityGridDesc t;
    t.file = g.file;
    t.gridName = "temperature";
    bool hasTemperature = true;
    try {
      media::loadDensityGridFile(t, at.str() + ": " + what, gridByteBudget(memoryAtStart_));
    } catch (const Error& e) {
      hasTemperature = std::string(e.what()).find("has no grid named") == std::string::npos;
    }
    double leScale = ps.has("Lescale") ? ps.getFloat("Lescale", 1) : ps.getFloat("LeScale", 1);
    for (const char* q : {"temperaturecutoff", "temperaturescale", "temperatureoffset"}) ps.markUsed(q);
    if (hasTemperature && leScale != 0)
      failAt(at, what + ": the file's \"temperature\" grid makes pbrt-v4's medium emit light, which tdpm does not support "
                        "(give \"float Lescale\" 0 to import it without emission)");
    return;
  }
  std::vector<double> d = ps.getFloats("density");
  if (d.empty()) failAt(at, what + ": missing parameter \"float density\"");
  if (ps.find("density")->type != "float") ps.fail(*ps.find("density"), "an RGB density (pbrt-v4's rgbgrid) is not supported; give float densities");
  int64_t nx = ps.getInt("nx", 1), ny = ps.getInt("ny", 1), nz = ps.getInt("nz", 1);
  if (nx < 1 || ny < 1 || nz < 1) failAt(at, what + ": nx, ny and nz must be at least 1");
  if (uint64_t(d.size()) != uint64_t(nx) * uint64_t(ny) * uint64_t(nz))
    ps.fail(*ps.find("density"), std::to_string(d.size()) + " values, expected nx x ny x nz = " + std::to_string(nx) + " x " +
                                     std::to_string(ny) + " x " + std::to_string(nz));
  g.nx = int(nx);
  g.ny = int(ny);
  g.nz = int(nz);
  g.density.reserve(d.size());
  for (size_t i = 0; i < d.size(); ++i) {
    if (!(std::isfinite(d[i]) && d[i] >= 0 && d[i] <= 3.4e38))
      ps.fail(*ps.find("density"), "value " + std::to_string(i) + " is " + fmtNum(d[i]) + "; densities must be finite and >= 0");
    g.density.push_back(float(d[i]));
  }
  Vec3f p0 = ps.getPoint("p0", {0, 0, 0}), p1 = ps.getPoint("p1", {1, 1, 1});
  if (!(p1.x > p0.x && p1.y > p0.y && p1.z > p0.z)) failAt(at, what + ": p1 must be above p0 on every axis");
  g.bounds = Bounds3f{p0, p1};
  std::vector<double> temperature = ps.getFloats("temperature");
  if (std::any_of(temperature.begin(), temperature.end(), [](double v) { return v != 0; }))
    ps.fail(*ps.find("temperature"), "a temperature grid makes the medium emit light, which tdpm does not support");
}

void Importer::makeNamedMedium(const std::string& name, const ParamSet& ps, const Loc& at) {
  const std::string what = "MakeNamedMedium \"" + name + "\"";
  if (name.empty()) failAt(at, what + ": a medium needs a name (\"\" is vacuum in MediumInterface)");
  if (namedMedia_.count(name)) failAt(at, what + ": a medium of that name has already been made");
  if (!ps.has("type")) failAt(at, what + ": missing parameter \"string type\"");
  std::string type = ps.getString("type", "");
  scene::MediumDesc m;
  m.name = name;
  bool v3 = pbrtV3() || type == "heterogeneous";
  if (type == "homogeneous") {
    m.type = scene::MediumDesc::Type::Homogeneous;
  } else if (type == "uniformgrid" || type == "heterogeneous" || type == "nanovdb") {
    mediumGrid(m, type, ps, at, what);
    mediumPlacement(m, at, what);
  } else if (type == "rgbgrid") {
    failAt(at, what + ": \"rgbgrid\" (RGB sigma_a / sigma_s per cell) is not supported: tdpm's grids hold one density that scales RGB coefficients");
  } else if (type == "cloud") {
    failAt(at, what + ": \"cloud\" (pbrt-v4's procedural noise cloud) is not supported: bake it into a uniformgrid or an OpenVDB/NanoVDB file");
  } else {
    failAt(at, what + ": unknown medium type \"" + type + "\" (homogeneous, uniformgrid, heterogeneous, nanovdb)");
  }
  mediumCoefficients(m, ps, what, v3);
  // pbrt-v4's emission: refused unless it is zero.
  Rgb Le = color(ps, "Le", Rgb(0.0f));
  double leScale = ps.has("Lescale") && ps.find("Lescale")->numbers.size() == 1 ? ps.getFloat("Lescale", 1) : 1;
  if (ps.has("Lescale")) ps.markUsed("Lescale");
  if (!Le.isBlack() && leScale != 0) failAt(at, what + ": an emissive medium (\"Le\") is not supported by tdpm");
  ps.checkAllUsed();
  namedMedia_[name] = int(result.scene.media.size());
  result.scene.media.push_back(std::move(m));
}

// ------------------------------------------------------------ who is in which medium

uint32_t Importer::interfaceMaterialIndex() {
  if (interfaceMaterial_ < 0) {
    scene::MaterialDesc d;
    d.type = scene::MaterialDesc::Type::Interface;
    d.name = "interface";  // the JSON's reserved name (materialNames_ keeps it free)
    result.scene.materials.push_back(d);
    interfaceMaterial_ = int(result.scene.materials.size()) - 1;
  }
  return uint32_t(interfaceMaterial_);
}

// pbrt: a shape whose two media are the same is no boundary (its
// GeometricPrimitive keeps the ray's medium), so only a MediumInterface
// with two different names makes one.
void Importer::objectMedia(const ShapeRecord& rec, size_t object) {
  if (rec.mediumInside == rec.mediumOutside) return;
  result.scene.objects[object].media.present = true;
  std::string user = "Shape \"" + rec.type + "\" at " + rec.at.str();
  mediumRefs_.push_back({MediumRef::Kind::ObjectInside, object, rec.mediumInside, rec.mediumAt, user});
  mediumRefs_.push_back({MediumRef::Kind::ObjectOutside, object, rec.mediumOutside, rec.mediumAt, user});
}

// An environment light is at infinity, in no medium (its photons start at
// the scene's bounds, in the medium there): its name is not recorded.
void Importer::lightMedium(const std::string& outside, const Loc& at, size_t light, const std::string& user) {
  if (light < result.scene.lights.size() && result.scene.lights[light].type == scene::LightDesc::Type::Environment) return;
  if (!outside.empty()) mediumRefs_.push_back({MediumRef::Kind::Light, light, outside, at, user});
}

void Importer::resolveMedia() {
  scene::SceneDescription& sc = result.scene;
  sc.exteriorMedium = -1;  // pbrt has no exterior medium: outside every boundary is what the camera's rays start in
  if (!cameraMedium_.empty()) mediumRefs_.push_back({MediumRef::Kind::Camera, 0, cameraMedium_, cameraMediumAt_, "the camera"});
  for (const MediumRef& r : mediumRefs_) {
    int32_t index = -1;
    if (!r.name.empty()) {
      auto it = namedMedia_.find(r.name);
      if (it == namedMedia_.end())
        failAt(r.at, std::string(r.kind == MediumRef::Kind::Camera ? "the camera's medium" : "MediumInterface") +
                         ": no medium named \"" + r.name + "\" has been made (MakeNamedMedium); used by " + r.user);
      index = it->second;
    }
    switch (r.kind) {
      case MediumRef::Kind::ObjectInside: sc.objects[r.index].media.inside = index; break;
      case MediumRef::Kind::ObjectOutside: sc.objects[r.index].media.outside = index; break;
      case MediumRef::Kind::Light: sc.lights[r.index].medium = index; break;
      case MediumRef::Kind::Camera: sc.camera.medium = index; break;
    }
  }
  // tdpm places a grid bounding an object in the object's space (it moves
  // with it); pbrt's grids stay in world space. The two agree only for an
  // object placed at the identity that does not move (every still mesh:
  // its placement is baked into its vertices).
  for (size_t i = 0; i < sc.objects.size(); ++i) {
    const scene::ObjectDesc& o = sc.objects[i];
    if (!o.media.present) continue;
    for (int32_t k : {o.media.inside, o.media.outside}) {
      if (k < 0 || sc.media[size_t(k)].type != scene::MediumDesc::Type::Grid) continue;
      const scene::TransformDesc& t = o.placement;
      bool identity = t.translate.x == 0 && t.translate.y == 0 && t.translate.z == 0 && t.scale.x == 1 && t.scale.y == 1 &&
                      t.scale.z == 1 && t.rotate.w == 1 && t.rotate.x == 0 && t.rotate.y == 0 && t.rotate.z == 0;
      if (!o.motion.empty() || !identity)
        failAt(objectAt_[i], o.name + ": its MediumInterface names the grid medium \"" + sc.media[size_t(k)].name +
                                 "\": tdpm places such a grid in the shape's own space, pbrt in world space; they agree "
                                 "only for a still triangle mesh (bound the grid with one)");
    }
  }
}

}  // namespace tdpm::pbrt::detail
