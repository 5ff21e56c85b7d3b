// import/pbrt_mapping.cpp — the mapping half of the pbrt import: pbrt
// materials, textures, lights and shapes (with their CTMs and motion) onto
// scene::SceneDescription, exactly or as a located error; the documented
// approximations leave a note. The statement half is pbrt_import.cpp.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>

#include "core/error.h"
#include "import/pbrt_importer.h"
#include "image/texture_image.h"
#include "import/ply_reader.h"
#include "scene/bsdf_pbrt.h"
#include "scene/environment.h"
#include "scene/json_writer.h"
#include "scene/limits.h"
#include "scene/subdivision.h"

namespace tdpm::pbrt::detail {

// ------------------------------------------------------------ materials / textures

static double roughnessToAlphaV3(double r) {
  double x = std::log(std::max(r, 1e-3));
  return 1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x + 0.000640711 * x * x * x * x;
}

Rgb Importer::color(const ParamSet& ps, const std::string& name, Rgb fallback) const {
  const Param* p = ps.find(name);
  if (!p) return fallback;
  p->used = true;
  if (p->type == "rgb") {
    if (p->numbers.size() != 3) ps.fail(*p, "expected 3 numbers");
    return {float(p->numbers[0]), float(p->numbers[1]), float(p->numbers[2])};
  }
  if (p->type == "float") {
    if (p->numbers.size() != 1) ps.fail(*p, "expected 1 number");
    return Rgb(float(p->numbers[0]));
  }
  if (p->type == "texture") {
    if (p->strings.size() != 1) ps.fail(*p, "expected one texture name");
    auto it = textures_.find(p->strings[0]);
    if (it == textures_.end()) ps.fail(*p, "no texture named \"" + p->strings[0] + "\" has been defined");
    if (!it->second.constant)
      ps.fail(*p, "a spectrum texture that varies is supported only on Kd of matte and plastic, reflectance of diffuse, "
                  "coateddiffuse, conductor and coatedconductor, Kr of mirror, Kr = Kt of glass, Ks of uber and substrate, "
                  "Kd, Ks and reflect of translucent, eta and k of metal, conductor and coatedconductor; here only a constant "
                  "texture is");
    return it->second.value;
  }
  if (p->type == "spectrum" || p->type == "blackbody") return spectrumColor(ps, *p);
  ps.fail(*p, "expected rgb, float, spectrum, blackbody or texture");
}

double Importer::floatParam(const ParamSet& ps, const std::string& name, double fallback) const {
  const Param* p = ps.find(name);
  if (!p) return fallback;
  if (p->type == "texture") {
    p->used = true;
    if (p->strings.size() != 1) ps.fail(*p, "expected one texture name");
    auto it = textures_.find(p->strings[0]);
    if (it == textures_.end()) ps.fail(*p, "no texture named \"" + p->strings[0] + "\" has been defined");
    if (!it->second.isFloat) ps.fail(*p, "expected a float texture");
    if (!it->second.constant) ps.fail(*p, "a float texture that varies is supported only as a roughness, a mix's amount, matte's sigma, "
                  "a coating's thickness, glass and uber eta, or a bump map; here only a constant one is");
    return it->second.value.r;
  }
  if (p->type == "spectrum") return spectrumFloat(ps, *p);  // v4: a spectral eta (a constant, a named glass, ...)
  return ps.getFloat(name, fallback);
}

scene::TexInput Importer::texInput(const ParamSet& ps, const std::string& name, bool isFloat, Rgb fallback,
                                   const std::string& what) const {
  scene::TexInput in;
  in.value = fallback;
  const Param* p = ps.find(name);
  if (!p) return in;
  if (p->type == "texture") {
    p->used = true;
    if (p->strings.size() != 1) ps.fail(*p, "expected one texture name");
    auto it = textures_.find(p->strings[0]);
    if (it == textures_.end()) ps.fail(*p, "no texture named \"" + p->strings[0] + "\" has been defined");
    if (it->second.isFloat != isFloat)
      ps.fail(*p, "texture \"" + p->strings[0] + "\" is a " + (it->second.isFloat ? "float" : "spectrum") + " texture, but " +
                      what + " needs a " + (isFloat ? "float" : "spectrum") + " one");
    in.texture = it->second.index;
    return in;
  }
  in.value = isFloat ? Rgb(float(floatParam(ps, name, fallback.r))) : color(ps, name, fallback);
  return in;
}

// pbrt-v3's "float bumpmap" and pbrt-v4's "float displacement" (a float
// texture: the surface displaced along its normal, JSON "bump"), pbrt-v4's
// "string normalmap" (an image read as linear RGB, as pbrt-v4 reads it;
// JSON "normal_map"). A constant displacement moves the whole surface and
// leaves its normal as it is, in pbrt too: nothing to map.
void Importer::shadingNormalParams(const ParamSet& ps, const Loc& at, const std::string& label,
                                   scene::MaterialDesc& m) {
  for (const char* key : {"bumpmap", "displacement"}) {
    if (!ps.has(key)) continue;
    int32_t t = varyingTexture(ps, key, true, "a bump map");
    if (t >= 0) m.bumpTexture = t;
    else (void)floatParam(ps, key, 0);
  }
  if (!ps.has("normalmap")) return;
  std::string file = ps.getString("normalmap", "");
  if (file.empty()) failAt(at, label + ": \"string normalmap\" must name an image file");
  m.normalMapFile = resolvePath(file, at.file, mainDir);
  image::TexelEncoding linear;
  linear.kind = image::TexelEncoding::Kind::Linear;
  auto key = std::make_pair(m.normalMapFile, image::encodingName(linear));
  auto& img = textureImages_[key];
  if (!img) {
    try {
      img = std::make_shared<const image::ImageRgb>(image::readTextureImage(m.normalMapFile, linear));
    } catch (const Error& e) {
      textureImages_.erase(key);
      failAt(at, label + ": normalmap: " + e.what());
    }
    result.inputFiles.push_back(m.normalMapFile);
  }
  m.normalMap = img;
}

// pbrt's imagemap: the file, its encoding, wrap, filter, scale and invert.
void Importer::imageTexture(scene::TextureDef& t, const ParamSet& ps, const Loc& at, const std::string& what) {
  t.kind = scene::TextureDef::Kind::Image;
  std::string file = ps.getString("filename", "");
  if (file.empty()) failAt(at, what + ": missing parameter \"string filename\"");
  t.file = resolvePath(file, at.file, mainDir);
  if (ps.has("encoding")) {  // pbrt-v4
    std::string e = ps.getString("encoding", "sRGB");
    if (e == "sRGB") t.encoding.kind = image::TexelEncoding::Kind::Srgb;
    else if (e == "linear") t.encoding.kind = image::TexelEncoding::Kind::Linear;
    else if (e.compare(0, 6, "gamma ") == 0 && std::strtod(e.c_str() + 6, nullptr) > 0)
      t.encoding = {image::TexelEncoding::Kind::Gamma, float(std::strtod(e.c_str() + 6, nullptr))};
    else failAt(at, what + ": unknown encoding \"" + e + "\" (sRGB, linear or \"gamma <g>\")");
  } else if (ps.has("gamma")) {  // pbrt-v3: true is sRGB
    t.encoding.kind = ps.getBool("gamma", true) ? image::TexelEncoding::Kind::Srgb : image::TexelEncoding::Kind::Linear;
  }
  std::string wrap = ps.getString("wrap", "repeat");
  if (wrap == "repeat") t.wrap = scene::TextureDef::Wrap::Repeat;
  else if (wrap == "clamp") t.wrap = scene::TextureDef::Wrap::Clamp;
  else if (wrap == "black") t.wrap = scene::TextureDef::Wrap::Black;
  else failAt(at, what + ": unknown wrap mode \"" + wrap + "\" (supported: repeat, clamp, black)");
  std::string filter = ps.getString("filter", "bilinear");
  if (filter == "point") t.filter = scene::TextureDef::Filter::Point;
  else if (filter != "bilinear" && filter != "trilinear" && filter != "ewa")
    failAt(at, what + ": unknown filter \"" + filter + "\" (point, bilinear, trilinear, ewa)");
  if (filter == "trilinear" || filter == "ewa" || ps.has("trilinear") || (pbrtV3() && !ps.has("filter")))
    note(at, what + ": MIP-map filtering (trilinear / EWA) approximated by bilinear lookups (tdpm supersamples instead)");
  for (const char* q : {"maxanisotropy", "trilinear"}) ps.markUsed(q);
  t.scale = float(ps.getFloat("scale", 1));
  if (!(t.scale >= 0)) failAt(at, what + ": scale must not be negative");
  t.invert = ps.getBool("invert", false);
  auto key = std::make_pair(t.file, image::encodingName(t.encoding));
  auto& img = textureImages_[key];
  if (!img) {
    try {
      img = std::make_shared<const image::ImageRgb>(image::readTextureImage(t.file, t.encoding));
    } catch (const Error& e) {
      textureImages_.erase(key);
      failAt(at, what + ": " + e.what());
    }
    result.inputFiles.push_back(t.file);
  }
  t.image = img;
}

void Importer::texture(const std::string& name, const std::string& kind, const std::string& type, const ParamSet& ps,
                       const Loc& at) {
  bool isFloat = kind == "float";
  const std::string what = "Texture \"" + name + "\"";
  if (!isFloat && kind != "spectrum" && kind != "color" && kind != "rgb")
    failAt(at, what + ": unknown texture kind \"" + kind + "\" (float, spectrum, or pbrt-v3's color/rgb)");
  scene::TextureDef t;
  t.name = name;
  t.isFloat = isFloat;
  TextureValue v;
  v.isFloat = isFloat;
  v.constant = type == "constant";
  auto mapping = [&]() {
    std::string m = ps.getString("mapping", "uv");
    if (m != "uv") failAt(at, what + ": only the \"uv\" mapping is supported, not \"" + m + "\"");
    t.uscale = float(ps.getFloat("uscale", 1));
    t.vscale = float(ps.getFloat("vscale", 1));
    t.udelta = float(ps.getFloat("udelta", 0));
    t.vdelta = float(ps.getFloat("vdelta", 0));
  };
  if (type == "constant") {
    t.kind = scene::TextureDef::Kind::Constant;
    v.value = isFloat ? Rgb(float(floatParam(ps, "value", 1.0))) : color(ps, "value", Rgb(1.0f));
    t.a.value = v.value;
  } else if (type == "scale") {
    t.kind = scene::TextureDef::Kind::Scale;
    if (ps.has("tex1") || ps.has("tex2")) {  // pbrt-v3: tex1 x tex2
      t.a = texInput(ps, "tex1", isFloat, Rgb(1.0f), what);
      t.b = texInput(ps, "tex2", isFloat, Rgb(1.0f), what);
    } else {
      t.a = texInput(ps, "tex", isFloat, Rgb(1.0f), what);
      t.b = texInput(ps, "scale", true, Rgb(1.0f), what + "'s scale");
    }
  } else if (type == "mix") {
    t.kind = scene::TextureDef::Kind::Mix;
    t.a = texInput(ps, "tex1", isFloat, Rgb(0.0f), what);
    t.b = texInput(ps, "tex2", isFloat, Rgb(1.0f), what);
    t.amount = texInput(ps, "amount", true, Rgb(0.5f), what + "'s amount");
  } else if (type == "checkerboard") {
    if (ps.getInt("dimension", 2) != 2)
      failAt(at, what + ": a 3D checkerboard is not supported (dimension 2 only: pbrt's 3D one lives in the texture's own space)");
    t.kind = scene::TextureDef::Kind::Checkerboard;
    mapping();
    t.a = texInput(ps, "tex1", isFloat, Rgb(1.0f), what);
    t.b = texInput(ps, "tex2", isFloat, Rgb(0.0f), what);
    for (const char* q : {"aamode", "filter"})
      if (ps.has(q)) ps.markUsed(q);
    note(at, what + ": the checkerboard's antialiasing filter is not applied (tdpm supersamples instead)");
  } else if (type == "imagemap") {
    mapping();
    imageTexture(t, ps, at, what);
  } else {
    failAt(at, what + ": type \"" + type + "\" is not supported (supported: constant, scale, mix, checkerboard, imagemap)");
  }
  ps.checkAllUsed();
  result.scene.textures.push_back(std::move(t));
  v.index = int32_t(result.scene.textures.size() - 1);
  textures_[name] = v;
}

int32_t Importer::varyingTexture(const ParamSet& ps, const std::string& name, bool isFloat, const std::string& what) const {
  const Param* p = ps.find(name);
  if (!p || p->type != "texture" || p->strings.size() != 1) return -1;
  auto it = textures_.find(p->strings[0]);
  if (it == textures_.end() || it->second.constant) return -1;
  p->used = true;
  if (it->second.isFloat != isFloat)
    ps.fail(*p, "texture \"" + p->strings[0] + "\" is a " + (it->second.isFloat ? "float" : "spectrum") + " texture, but " +
                    what + " needs a " + (isFloat ? "float" : "spectrum") + " one");
  return it->second.index;
}

Rgb Importer::textureParam(const ParamSet& ps, const std::string& name, Rgb fallback, int32_t* index) const {
  if (int32_t t = varyingTexture(ps, name, false, "a reflectance"); t >= 0) {
    *index = t;
    return Rgb(0.5f);  // not used: the texture is (clamped to [0, 1] when evaluated)
  }
  return color(ps, name, fallback);
}

void Importer::translucentLobe(const std::string& name, Rgb* value, int32_t* texture, Rgb reflect, int32_t reflectTexture) {
  if (*texture < 0 && reflectTexture < 0) {
    *value = *value * reflect;
    return;
  }
  scene::TextureDef t;
  t.name = name + " x reflect";
  t.kind = scene::TextureDef::Kind::Scale;  // a x b per hit, in the constant path's order
  t.a = {*texture, *value};
  t.b = {reflectTexture, reflect};
  result.scene.textures.push_back(std::move(t));
  *texture = int32_t(result.scene.textures.size() - 1);
}

static void checkReflectance(const ParamSet& ps, const std::string& name, Rgb c) {
  if (c.r < 0 || c.g < 0 || c.b < 0 || c.maxComponent() > 1) {
    if (const Param* p = ps.find(name)) ps.fail(*p, "reflectance must be in [0, 1] per channel (energy conservation)");
    throw Error(ps.file() + ": " + ps.statement() + ": " + name + " must be in [0, 1]");
  }
}

MaterialSlot Importer::makeMaterial(const std::string& type, const ParamSet& ps, const Loc& at, const std::string& name) {
  using T = scene::MaterialDesc::Type;
  MaterialSlot slot;
  scene::MaterialDesc& m = slot.desc;
  std::string label = name.empty() ? type : name;
  // pre: the parameter prefix ("interface.", "conductor." of coatedconductor).
  // A varying float texture on pre + "roughness" (or the same one on
  // "uroughness" and "vroughness"): its index, else -1 (a constant).
  auto varyingRoughness = [&](const std::string& pre) -> int32_t {
    auto tex = [&](const std::string& key) -> int32_t {
      const Param* p = ps.find(key);
      if (!p || p->type != "texture" || p->strings.size() != 1) return -1;
      auto it = textures_.find(p->strings[0]);
      if (it == textures_.end() || it->second.constant) return -1;
      p->used = true;
      if (!it->second.isFloat)
        ps.fail(*p, "texture \"" + p->strings[0] + "\" is a spectrum texture, but a roughness needs a float one");
      return it->second.index;
    };
    int32_t r = tex(pre + "roughness");
    int32_t u = ps.has(pre + "uroughness") ? tex(pre + "uroughness") : r;
    int32_t v = ps.has(pre + "vroughness") ? tex(pre + "vroughness") : r;
    if (u != v)
      failAt(at, label + ": anisotropic roughness (" + pre + "uroughness and " + pre + "vroughness not the same texture) is not supported");
    return u;
  };
  // texture: where a textured roughness goes.
  auto roughnessPre = [&](const std::string& pre, bool v3, double fallback, double* alpha, int32_t* texture) {
    if (int32_t t = varyingRoughness(pre); t >= 0) {
      *texture = t;
      using R = scene::MaterialDesc::Remap;
      m.roughnessRemap = !ps.getBool("remaproughness", true) ? R::None : v3 ? R::PbrtV3 : R::PbrtV4;
      *alpha = 1.0;  // not used: the texture is, per hit (scene/build.cpp classifies from its range)
      return;
    }
    double u = floatParam(ps, pre + "uroughness", floatParam(ps, pre + "roughness", fallback));
    double v = floatParam(ps, pre + "vroughness", floatParam(ps, pre + "roughness", fallback));
    if (u != v)
      failAt(at, label + ": anisotropic roughness (" + pre + "uroughness != " + pre + "vroughness) is not supported");
    bool remap = ps.getBool("remaproughness", true);
    if (u < 0) failAt(at, label + ": roughness must not be negative");
    *alpha = !remap || u == 0 ? u : (v3 ? roughnessToAlphaV3(u) : std::sqrt(u));
    if (*alpha > 1) failAt(at, label + ": roughness maps to GGX alpha " + fmtNum(*alpha) + " > 1, which tdpm does not support");
  };
  auto roughness = [&](bool v3, double fallback, double* alpha) {
    roughnessPre("", v3, fallback, alpha, &m.roughnessTexture);
  };
  // A conductor's complex IOR: pre + "eta" / "k" (pbrt's default: copper),
  // or pbrt-v4's "reflectance" r, which is eta = 1, k = 2 sqrt(r) / sqrt(1 - r).
  auto conductorIor = [&](bool v3, const std::string& pre, Rgb* eta, Rgb* k) {
    if (!v3 && ps.has("reflectance")) {
      int32_t tex = -1;
      Rgb r = textureParam(ps, "reflectance", Rgb(1.0f), &tex);
      if (tex >= 0) {
        m.specularTexture = tex;  // eta = 1, k from r per hit (Scene::shadedMaterial; / ior under a coating)
        *eta = Rgb(1.0f);
        *k = Rgb(0.0f);
        return;
      }
      checkReflectance(ps, "reflectance", r);
      *eta = Rgb(1.0f);
      for (int i = 0; i < 3; ++i) {
        float ri = std::min(r[i], 0.9999f);
        (*k)[i] = 2.0f * std::sqrt(ri) / std::sqrt(1.0f - ri);
      }
      return;
    }
    // pbrt's default is copper (pbrt_spectrum.cpp: v3 reduces its copper
    // against equal-energy white, v4 its metal-Cu under D65).
    bool filmV3 = v3 || (film_.given && film_.type == "image");
    Rgb cuEta = filmV3 ? Rgb(0.200964f, 0.923779f, 1.102306f) : Rgb(0.105133f, 0.977933f, 1.204671f);
    Rgb cuK = filmV3 ? Rgb(3.912923f, 2.453080f, 2.142269f) : Rgb(3.273486f, 2.592516f, 2.369186f);
    // Either may be a spectrum texture (pbrt-v3's and v4's conductors take
    // textures there): per hit, eta kept >= 1e-3 and k >= 0 (Scene::shadedMaterial).
    m.etaTexture = varyingTexture(ps, pre + "eta", false, "a conductor's eta");
    m.kTexture = varyingTexture(ps, pre + "k", false, "a conductor's k");
    *eta = m.etaTexture >= 0 ? Rgb(1.0f) : color(ps, pre + "eta", cuEta);
    *k = m.kTexture >= 0 ? Rgb(0.0f) : color(ps, pre + "k", cuK);
    if (!(eta->r > 0 && eta->g > 0 && eta->b > 0)) failAt(at, label + ": " + pre + "eta must be positive");
    if (k->r < 0 || k->g < 0 || k->b < 0) failAt(at, label + ": " + pre + "k must not be negative");
  };
  // pbrt-v3's glass and uber: eta (or index) is a FloatTexture; a varying
  // one per hit (m.iorTexture; build.cpp refuses values below 1).
  auto v3Eta = [&]() -> double {
    const std::string key = ps.has("eta") ? "eta" : "index";
    m.iorTexture = varyingTexture(ps, key, true, "an index of refraction");
    if (m.iorTexture >= 0) return 1.5;  // not used: the texture is, per hit
    return floatParam(ps, "eta", ps.has("index") ? floatParam(ps, "index", 1.5) : 1.5);
  };
  if (type == "" || type == "interface" || type == "none") {
    slot.interface = true;
  } else if (type == "matte" || type == "diffuse") {
    m.type = T::Diffuse;
    std::string key = type == "matte" ? "Kd" : "reflectance";
    m.albedo.color = textureParam(ps, key, Rgb(0.5f), &m.albedoTexture);
    checkReflectance(ps, key, m.albedo.color);
    if (type == "matte") {
      // pbrt-v3's matte: Oren-Nayar when sigma (degrees; a FloatTexture, per
      // hit) is not 0, sigma clamped to [0, 90] as pbrt-v3 clamps it.
      m.sigmaTexture = varyingTexture(ps, "sigma", true, "matte's sigma");
      if (m.sigmaTexture < 0) {
        double sigma = floatParam(ps, "sigma", 0);
        if (!(sigma >= 0 && sigma <= 90)) {
          note(at, label + ": sigma " + fmtNum(sigma) + " clamped to [0, 90] degrees, as pbrt-v3 does");
          sigma = std::isnan(sigma) ? 0.0 : std::clamp(sigma, 0.0, 90.0);
        }
        m.sigma = float(sigma);
      }
    }
  } else if (type == "mirror") {
    m.type = T::Mirror;
    m.specular = textureParam(ps, "Kr", Rgb(0.9f), &m.specularTexture);
    checkReflectance(ps, "Kr", m.specular);
  } else if (type == "glass" || type == "dielectric") {
    double eta = type == "glass" ? v3Eta() : floatParam(ps, "eta", ps.has("index") ? floatParam(ps, "index", 1.5) : 1.5);
    if (!(eta >= 1)) failAt(at, label + ": eta " + fmtNum(eta) + " below 1 is not supported");
    m.ior = float(eta);
    double alpha;
    roughness(type == "glass", 0, &alpha);
    // Rough: GGX microfacet reflection and transmission (scene/bsdf_pbrt.cpp).
    m.type = alpha < kSmoothAlpha && m.roughnessTexture < 0 ? T::Dielectric : T::RoughDielectric;
    m.roughness = float(alpha);
    if (type == "glass") {
      int32_t tr = -1, tt = -1;
      Rgb kr = textureParam(ps, "Kr", Rgb(1.0f), &tr), kt = textureParam(ps, "Kt", Rgb(1.0f), &tt);
      m.specularTexture = tr;
      if (tr != tt || kr.r != kt.r || kr.g != kt.g || kr.b != kt.b)
        failAt(at, label + ": Kr and Kt differ; tdpm's dielectric has one tint for reflection and transmission");
      checkReflectance(ps, "Kr", kr);
      m.specular = kr;
    }
  } else if (type == "metal" || type == "conductor") {
    bool v3 = type == "metal";
    conductorIor(v3, "", &m.eta, &m.k);
    double alpha;
    roughness(v3, v3 ? 0.01 : 0.0, &alpha);
    m.type = T::Conductor;  // alpha < 1e-3: smooth (scene/build.cpp)
    m.roughness = float(alpha);
  } else if (type == "plastic" || type == "uber" || type == "translucent" || type == "substrate") {
    // pbrt-v3's plastic is exactly uber without Kr, Kt (Kd + Ks with
    // dielectric Fresnel at eta 1.5); translucent keeps its reflection lobes.
    bool substrate = type == "substrate";
    m.type = substrate ? T::Substrate : T::Uber;
    Rgb kdDefault(type == "plastic" || type == "uber" || type == "translucent" ? 0.25f : 0.5f);
    m.albedo.color = textureParam(ps, "Kd", kdDefault, &m.albedoTexture);
    checkReflectance(ps, "Kd", m.albedo.color);
    m.specular = textureParam(ps, "Ks", Rgb(substrate ? 0.5f : 0.25f), &m.specularTexture);
    checkReflectance(ps, "Ks", m.specular);
    double alpha;
    roughness(true, 0.1, &alpha);
    m.roughness = float(std::max(alpha, 1e-3));
    m.ior = 1.5f;
    if (type == "uber") {
      double eta = v3Eta();
      if (!(eta >= 1)) failAt(at, label + ": eta " + fmtNum(eta) + " below 1 is not supported");
      m.ior = float(eta);
      Rgb kr = color(ps, "Kr", Rgb(0.0f)), kt = color(ps, "Kt", Rgb(0.0f)), op = color(ps, "opacity", Rgb(1.0f));
      if (op.r != 1 || op.g != 1 || op.b != 1) failAt(at, label + ": uber's opacity below 1 is not supported");
      if (!kr.isBlack() || !kt.isBlack()) {
        if (!m.albedo.color.isBlack() || !m.specular.isBlack() || m.albedoTexture >= 0)
          failAt(at, label + ": uber with specular lobes (Kr, Kt) beside Kd or Ks is not supported "
                             "(tdpm's materials are delta-only or not at all)");
        if (kr.r != kt.r || kr.g != kt.g || kr.b != kt.b)
          failAt(at, label + ": uber's Kr and Kt differ; tdpm's dielectric has one tint for reflection and transmission");
        checkReflectance(ps, "Kr", kr);
        m.type = T::Dielectric;  // Kr Fresnel reflection + Kt Fresnel transmission: pbrt-v3's glass
        m.specular = kr;
      }
    } else if (type == "translucent") {
      int32_t rt = -1, tt = -1;
      Rgb r = textureParam(ps, "reflect", Rgb(0.5f), &rt);
      textureParam(ps, "transmit", Rgb(0.5f), &tt);  // dropped with the transmission (below)
      translucentLobe(label + ".Kd", &m.albedo.color, &m.albedoTexture, r, rt);
      translucentLobe(label + ".Ks", &m.specular, &m.specularTexture, r, rt);
      note(at, label + ": translucent approximated by its reflection lobes alone (Lambert reflect x Kd and GGX "
                       "reflect x Ks, as uber); its transmission is dropped (see docs/pbrt-import.md)");
    }
  } else if (type == "coateddiffuse" || type == "coatedconductor") {
    bool diffuse = type == "coateddiffuse";
    std::string pre = diffuse ? "" : "interface.";
    double eta = floatParam(ps, pre + "eta", 1.5);
    if (!(eta >= 1)) failAt(at, label + ": eta below 1 is not supported");
    m.ior = float(eta);
    double alpha;
    roughnessPre(pre, false, 0.0, &alpha, &m.roughnessTexture);
    m.roughness = float(std::max(alpha, 1e-3));
    if (diffuse) {
      m.type = T::CoatedDiffuse;
      m.albedo.color = textureParam(ps, "reflectance", Rgb(0.5f), &m.albedoTexture);
      checkReflectance(ps, "reflectance", m.albedo.color);
    } else {
      m.type = T::CoatedConductor;
      conductorIor(false, "conductor.", &m.eta, &m.k);
      double base;
      roughnessPre("conductor.", false, 0.0, &base, &m.baseRoughnessTexture);
      m.baseRoughness = float(std::max(base, 1e-3));
    }
    // A FloatTexture: per hit (Scene::shadedMaterial; build.cpp refuses values below 0).
    m.thicknessTexture = varyingTexture(ps, "thickness", true, "a coating's thickness");
    if (m.thicknessTexture < 0) m.thickness = float(floatParam(ps, "thickness", 0.01));
    if (!(m.thickness >= 0)) failAt(at, label + ": thickness must not be negative");
    Rgb albedo = color(ps, "albedo", Rgb(0.0f));
    if (!albedo.isBlack()) failAt(at, label + ": a coating with a scattering albedo is not supported");
    for (const char* q : {"g", "maxdepth", "nsamples"}) ps.markUsed(q);
    note(at, label + ": " + type + " approximated in closed form (scene/bsdf_pbrt.cpp: the coating's GGX lobe plus "
                     "the base seen through a smooth interface; measured against a random walk in "
                     "tests/test_materials.cpp; docs/pbrt-import.md)");
  } else if (type == "mix") {
    const Param* p = ps.find("materials");
    if (!p || p->strings.size() != 2) failAt(at, label + ": mix needs \"string materials\" with two named materials");
    p->used = true;
    for (int i = 0; i < 2; ++i) {
      auto it = namedMaterials_.find(p->strings[size_t(i)]);
      if (it == namedMaterials_.end())
        ps.fail(*p, "no material named \"" + p->strings[size_t(i)] + "\" has been made");
      const MaterialSlot& c = materials_[size_t(it->second)];
      if (c.interface) ps.fail(*p, "material \"" + p->strings[size_t(i)] + "\" is an interface; a mix needs surfaces");
      slot.mixSlots[i] = it->second;
    }
    m.type = T::Mix;
    // pbrt-v3's amount is a Spectrum (an rgb / spectrum value or texture):
    // its MixMaterial scales the first material's BSDF by amount and the
    // second's by 1 - amount, per channel. tdpm's per-channel mix weights
    // its second material by amount: the two are swapped.
    const Param* a = ps.find("amount");
    auto it = a && a->type == "texture" && a->strings.size() == 1 ? textures_.find(a->strings[0]) : textures_.end();
    if (a && a->type != "float" && (a->type != "texture" || it == textures_.end() || !it->second.isFloat)) {
      m.amountPerChannel = true;
      std::swap(slot.mixSlots[0], slot.mixSlots[1]);
      m.amountTexture = varyingTexture(ps, "amount", false, "a mix's amount");
      if (m.amountTexture < 0) {
        m.amountRgb = color(ps, "amount", Rgb(0.5f));
        for (int i = 0; i < 3; ++i) m.amountRgb[i] = std::clamp(m.amountRgb[i], 0.0f, 1.0f);  // pbrt-v3's Clamp()
      }
    } else {
      // pbrt-v4's amount is a FloatTexture: per hit (Scene::materialAt); a
      // value outside [0, 1] there picks one component, as in pbrt.
      m.amountTexture = varyingTexture(ps, "amount", true, "a mix's amount");
      if (m.amountTexture < 0) m.amount = float(floatParam(ps, "amount", 0.5));
      if (!(m.amount >= 0 && m.amount <= 1)) failAt(at, label + ": amount must be in [0, 1]");
    }
  } else if (type == "measured") {
    failAt(at, label + ": measured BSDFs (tabulated \"filename\" data) are not supported: tdpm has no tabulated "
                       "BSDF; use a conductor or coateddiffuse of similar appearance");
  } else {
    failAt(at, "material type \"" + type + "\" is not supported (see docs/pbrt-import.md)");
  }
  if (!slot.interface && m.type != T::Mix) shadingNormalParams(ps, at, label, m);
  ps.markUsed("type");
  ps.checkAllUsed();
  m.name = name;  // unique names are given when a shape first uses the material
  return slot;
}

std::string Importer::uniqueMaterialName(const std::string& base) {
  std::string name = base;
  for (int i = 2; materialNames_.count(name); ++i) name = base + "#" + std::to_string(i);
  materialNames_.insert(name);
  return name;
}

uint32_t Importer::materialIndex(int slot) {
  MaterialSlot& s = materials_[size_t(slot)];
  if (s.index < 0) {
    scene::MaterialDesc d = s.desc;
    if (d.type == scene::MaterialDesc::Type::Mix)  // its components first (they were made before it)
      for (int i = 0; i < 2; ++i) d.mix[i] = materialIndex(s.mixSlots[i]);
    d.name = uniqueMaterialName(d.name.empty() ? "material" + std::to_string(slot) : d.name);
    result.scene.materials.push_back(d);
    s.index = int(result.scene.materials.size()) - 1;
  }
  return uint32_t(s.index);
}

// ------------------------------------------------------------ lights

// pbrt's light sample counts only change noise: ignored, with one note.
void Importer::noteLightSamples(const ParamSet& ps, const Loc& at, const std::string& what) {
  for (const char* q : {"nsamples", "samples"})
    if (ps.has(q)) {
      ps.markUsed(q);
      note(at, what + ": \"" + q + "\" ignored (quality only: tdpm chooses its own light samples)");
    }
}

Rgb Importer::lightScale(const ParamSet& ps) const {
  const Param* p = ps.find("scale");
  if (!p) return Rgb(1.0f);
  return color(ps, "scale", Rgb(1.0f));  // float (v4) or rgb (v3)
}

static Rgb nonNegative(const ParamSet& ps, const std::string& name, Rgb c) {
  if (c.r < 0 || c.g < 0 || c.b < 0) {
    if (const Param* p = ps.find(name)) ps.fail(*p, "must be non-negative in every channel");
  }
  return c;
}

void Importer::lightSource(const std::string& type, const ParamSet& ps, const Loc& at) {
  if (currentInstance_) failAt(at, "LightSource inside an object definition is not supported");
  Mat W = mirror_ ? mirrorX() : Mat();
  Mat M = W * gs_.ctm[0];
  if (!(gs_.ctm[0] == gs_.ctm[1]))
    note(at, "LightSource: lights do not move in pbrt; the StartTime transform is used (as pbrt does)");
  Rgb sc = lightScale(ps);
  double power = ps.has("power") ? ps.getFloat("power", -1) : -1;
  noteLightSamples(ps, at, "LightSource \"" + type + "\"");
  scene::LightDesc l;
  l.name = "LightSource \"" + type + "\" (" + at.str() + ")";
  if (type == "point") {
    Rgb I = nonNegative(ps, "I", color(ps, "I", Rgb(1.0f))) * sc;
    if (power > 0) I = I * float(power / (4 * kPiD));
    l.type = scene::LightDesc::Type::Point;
    l.position = M.point(ps.getPoint("from", {0, 0, 0}));
    l.power = I * float(4 * kPiD);
  } else if (type == "spot") {
    Rgb I = nonNegative(ps, "I", color(ps, "I", Rgb(1.0f))) * sc;
    double cone = ps.getFloat("coneangle", 30), delta = ps.getFloat("conedeltaangle", 5);
    if (!(cone > 0 && cone <= 90)) failAt(at, "LightSource \"spot\": coneangle must be in (0, 90] degrees for tdpm, got " + fmtNum(cone));
    if (!(delta >= 0 && delta <= cone)) failAt(at, "LightSource \"spot\": conedeltaangle must be in [0, coneangle], got " + fmtNum(delta));
    double cosT = std::cos(cone * kPiD / 180), cosS = std::cos((cone - delta) * kPiD / 180);
    if (power > 0) I = I * float(power / (2 * kPiD * ((1 - cosS) + (cosS - cosT) / 2)));  // pbrt-v4's k_e
    Vec3f from = ps.getPoint("from", {0, 0, 0}), to = ps.getPoint("to", {0, 0, 1});
    std::string degenerate = scaleProblem(M);
    if (!degenerate.empty()) failAt(at, "LightSource \"spot\": its transform is unusable: " + degenerate);
    Vec3f dir = M.vector(to - from);
    if (!(length(dir) > 0)) failAt(at, "LightSource \"spot\": from and to coincide");
    std::optional<Pose> p = decompose(M);
    if (!p || std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.y)) > 1e-5f * std::fabs(p->scale.x) ||
        std::fabs(std::fabs(p->scale.x) - std::fabs(p->scale.z)) > 1e-5f * std::fabs(p->scale.x))
      failAt(at, "LightSource \"spot\": a non-uniform scale or shear would distort the cone; not supported");
    l.type = scene::LightDesc::Type::Spot;
    l.position = M.point(from);
    l.direction = canonicalDirection(normalize(dir));
    l.coneAngle = float(cone);
    l.falloffStart = float(cone - delta);
    float solid = float(2 * kPiD * ((1 - cosS) + (cosS - cosT) / 5));  // tdpm's exact integral of the quartic falloff
    l.power = I * solid;
    // Exact for pbrt-v3 (Film "image"); a pbrt-v4 or unmarked file is told.
    if (delta > 0 && !pbrtV3())
      note(at, "LightSource \"spot\": the falloff band uses pbrt-v3's quartic curve; pbrt-v4 uses smoothstep there");
  } else if (type == "distant") {
    if (power > 0) failAt(at, "LightSource \"distant\": \"power\" depends on pbrt's scene radius; give L instead");
    Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * sc;
    Vec3f from = ps.getPoint("from", {0, 0, 0}), to = ps.getPoint("to", {0, 0, 1});
    Vec3f dir = M.vector(to - from);
    if (!(length(dir) > 0)) failAt(at, "LightSource \"distant\": from and to coincide");
    l.type = scene::LightDesc::Type::Directional;
    l.direction = canonicalDirection(normalize(dir));  // pbrt's light travels from "from" toward "to"
    l.power = L;                   // irradiance on a surface facing the light
  } else if (type == "infinite") {
    environmentLight(ps, M, at);
    return;
  } else {
    failAt(at, "LightSource \"" + type + "\" is not supported (point, spot, distant, infinite)");
  }
  ps.checkAllUsed();
  result.scene.lights.push_back(l);
  lightAt_.push_back(at);
}

// pbrt's "infinite" light: constant L, a pbrt-v3 lat-long "mapname", or a
// pbrt-v4 equal-area square "filename"; pbrt-v4's "illuminance" scales it so
// that the upper hemisphere (light-space +z) gives that illuminance on a
// surface facing +z. Translation is ignored, as pbrt does.
void Importer::environmentLight(const ParamSet& ps, const Mat& M, const Loc& at) {
  const std::string what = "LightSource \"infinite\"";
  if (ps.has("power")) failAt(at, what + ": \"power\" is not supported; give L, scale or illuminance");
  if (ps.has("portal")) failAt(at, what + ": \"portal\" is not supported (it only changes pbrt's sampling; remove it)");
  if (ps.has("filename") && ps.has("mapname")) failAt(at, what + ": give \"filename\" or \"mapname\", not both");
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Environment;
  l.name = "LightSource \"infinite\" (" + at.str() + ")";
  Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * lightScale(ps);
  for (const char* key : {"filename", "mapname"}) {
    if (!ps.has(key)) continue;
    std::string file = ps.getString(key, "");
    if (file.empty()) failAt(at, what + ": \"" + key + "\" is empty");
    l.mapFile = resolvePath(file, at.file, mainDir);
    l.equalArea = std::string(key) == "filename";  // pbrt-v4 names it filename and wants it equal-area
    std::string problem;
    l.map = loadEnvironmentMap(l.mapFile, l.equalArea, &problem);
    if (!l.map) failAt(at, what + ": " + problem);
  }
  double illuminance = ps.has("illuminance") ? ps.getFloat("illuminance", -1) : -1;
  if (ps.has("illuminance") && !(illuminance > 0 && std::isfinite(illuminance)))
    failAt(at, what + ": \"illuminance\" must be positive, got " + fmtNum(illuminance));
  if (illuminance > 0) {
    // pbrt-v4 k_e: pi for a constant (its spectrum's own luminance normalised
    // away, as for RGB in pbrt-v4), the map's hemisphere integral otherwise.
    double ke = l.map ? upperHemisphereIlluminance(*l.map) : kPiD;
    if (!(ke > 0)) failAt(at, what + ": \"illuminance\" with a map that is black over its upper hemisphere");
    L = L * float(illuminance / ke);
  }
  for (const char* q : {"nsamples", "samples"}) ps.markUsed(q);
  ps.checkAllUsed();
  std::optional<Pose> pose = decompose(M);
  if (!pose) failAt(at, what + ": the light's transform has shear (not a rotation and scale)");
  Vec3f a{std::fabs(pose->scale.x), std::fabs(pose->scale.y), std::fabs(pose->scale.z)};
  if (std::fabs(a.x - a.y) > 1e-5f * a.x || std::fabs(a.y - a.z) > 1e-5f * a.y)
    failAt(at, what + ": the light's transform has a non-uniform scale, which would distort the map (pbrt does not "
                      "correct its densities for it); not supported");
  // Only the rotation and mirror matter: write unit scales (exactly uniform).
  pose->scale = {std::copysign(1.0f, pose->scale.x), std::copysign(1.0f, pose->scale.y), std::copysign(1.0f, pose->scale.z)};
  l.placement.rotate = canonicalRotation(pose->rotate);
  l.placement.scale = pose->scale;
  l.radiance = L;
  result.scene.lights.push_back(l);
}

// ------------------------------------------------------------ shapes

void Importer::shape(const std::string& type, ParamSet params, const Loc& at) {
  ShapeRecord rec{type, std::move(params), {gs_.ctm[0], gs_.ctm[1]}, gs_.material, gs_.area, at, gs_.reverseOrientation,
                  gs_.mediumInside, gs_.mediumOutside, gs_.mediumAt};
  if (currentInstance_) {
    if (rec.area) failAt(at, "Shape: area lights inside an object definition are not supported (pbrt ignores them too)");
    currentInstance_->push_back(std::move(rec));
    return;
  }
  Mat ctm[2] = {gs_.ctm[0], gs_.ctm[1]};
  emitShape(rec, ctm, {});
}

namespace {
struct Geometry {
  bool sphere = false;
  float radius = 1;
  // disk / cylinder: their ShapeDesc fields (type, radius, inner radius, height, z range, phi max)
  std::optional<scene::ShapeDesc> quadric;
  std::vector<Vec3f> vertices;
  std::vector<uint32_t> indices;
  std::vector<Vec2f> uv;  // per vertex, when the file gives them (or a single bilinear patch's defaults)
  std::vector<Vec3f> normals;  // shading normals N / nx ny nz per vertex (object space), or empty
  int loopLevels = -1;    // loopsubdiv: the control mesh above, refined by scene/build.cpp
};
}  // namespace

static std::vector<Vec3f> readPoints(const ParamSet& ps, const std::string& name, const Loc& at) {
  const Param* p = ps.find(name);
  if (!p) failAt(at, ps.statement() + ": missing parameter \"point3 " + name + "\"");
  if (p->type != "point3") ps.fail(*p, "expected type point3");
  std::vector<double> v = ps.getFloats(name);
  if (v.empty() || v.size() % 3) ps.fail(*p, "expected a non-empty multiple of 3 numbers, got " + std::to_string(v.size()));
  std::vector<Vec3f> out;
  for (size_t i = 0; i < v.size(); i += 3) out.push_back({float(v[i]), float(v[i + 1]), float(v[i + 2])});
  return out;
}

static std::vector<uint32_t> readIndices(const ParamSet& ps, size_t vertexCount, size_t per, const std::string& what,
                                         const Loc& at) {
  const Param* p = ps.find("indices");
  std::vector<uint32_t> out;
  if (!p) {
    if (vertexCount != per)
      failAt(at, ps.statement() + ": missing parameter \"integer indices\" (only a single " + what + " of " +
                     std::to_string(per) + " points may omit it)");
    for (uint32_t i = 0; i < per; ++i) out.push_back(i);
    return out;
  }
  std::vector<int64_t> v = ps.getInts("indices");
  if (v.empty() || v.size() % per)
    ps.fail(*p, "expected a non-empty multiple of " + std::to_string(per) + " indices, got " + std::to_string(v.size()));
  for (int64_t i : v) {
    if (i < 0 || uint64_t(i) >= vertexCount)
      ps.fail(*p, "index " + std::to_string(i) + " is out of range (there are " + std::to_string(vertexCount) + " points)");
    out.push_back(uint32_t(i));
  }
  return out;
}

// Appends quads (a, b, c, d in the file's corner order) as two triangles:
// exact only for flat parallelograms, where pbrt-v3's triangle split and
// pbrt-v4's bilinear patch agree.
static void addQuads(const std::vector<Vec3f>& P, const std::vector<uint32_t>& quads, const Loc& at, const std::string& what,
              std::vector<uint32_t>* triangles) {
  for (size_t i = 0; i < quads.size(); i += 4) {
    Vec3f a = P[quads[i]], b = P[quads[i + 1]], c = P[quads[i + 2]], d = P[quads[i + 3]];
    float scale = std::max({length(b - a), length(d - a), 1e-30f});
    if (length((a + c) - (b + d)) > 1e-5f * scale)
      failAt(at, what + ": quad " + std::to_string(i / 4) + " is not a flat parallelogram (pbrt-v3 and v4 would render it differently)");
    triangles->insert(triangles->end(), {quads[i], quads[i + 1], quads[i + 2], quads[i], quads[i + 2], quads[i + 3]});
  }
}

// pbrt's "integer levels" (default 3; pbrt-v3 also reads the older
// "nlevels"), checked against the refined-triangle budget before anything
// is refined.
static int readLoopLevels(const ParamSet& ps, size_t triangles, const Loc& at) {
  const char* name = ps.has("levels") || !ps.has("nlevels") ? "levels" : "nlevels";
  const Param* p = ps.find(name);
  if (ps.has("nlevels") && ps.has("levels")) ps.fail(*ps.find("nlevels"), "give \"levels\" or \"nlevels\", not both");
  int levels = ps.getInt(name, 3);
  if (levels < 0) ps.fail(*p, "levels must be >= 0, got " + std::to_string(levels));
  uint64_t refined = scene::loopTriangleCount(triangles, levels);
  if (refined > scene::limits::kMaxSubdividedTriangles) {
    std::string what = std::to_string(levels) + " levels refine the " + std::to_string(triangles) + " triangles to " +
                       (refined == UINT64_MAX ? std::string("more than 2^64") : std::to_string(refined)) +
                       " triangles, more than tdpm's limit of " + std::to_string(scene::limits::kMaxSubdividedTriangles);
    if (p) ps.fail(*p, what);
    failAt(at, "Shape \"loopsubdiv\": " + what + " (the default is 3 levels)");
  }
  return levels;
}

// pbrt's disk (radius 1, innerradius 0, height 0, phimax 360) and cylinder
// (radius 1, zmin -1, zmax 1, phimax 360), checked as pbrt would draw them:
// an empty or inside-out surface is an error, not nothing.
static scene::ShapeDesc readQuadric(const ShapeRecord& rec) {
  const ParamSet& ps = rec.params;
  const std::string what = "Shape \"" + rec.type + "\"";
  scene::ShapeDesc q;
  auto finite = [&](const char* name, double v) {
    if (!std::isfinite(float(v))) ps.fail(*ps.find(name), std::string(name) + " must be a finite number");
    return float(v);
  };
  double r = ps.getFloat("radius", 1);
  if (!(r > 0)) failAt(rec.at, what + ": radius must be positive, got " + fmtNum(r));
  q.radius = finite("radius", r);
  double phimax = ps.getFloat("phimax", 360);
  if (!(phimax > 0)) failAt(rec.at, what + ": phimax must be positive, got " + fmtNum(phimax));
  q.phiMax = float(std::min(phimax, 360.0));  // pbrt clamps to [0, 360]
  if (rec.type == "disk") {
    q.type = scene::ShapeDesc::Type::Disk;
    double inner = ps.getFloat("innerradius", 0);
    if (!(inner >= 0)) failAt(rec.at, what + ": innerradius must be >= 0, got " + fmtNum(inner));
    if (!(inner < r))
      failAt(rec.at, what + ": innerradius " + fmtNum(inner) + " must be below radius " + fmtNum(r) + " (the disk would be empty)");
    q.innerRadius = float(inner);
    q.height = ps.has("height") ? finite("height", ps.getFloat("height", 0)) : 0.0f;
  } else {
    q.type = scene::ShapeDesc::Type::Cylinder;
    double zmin = ps.getFloat("zmin", -1), zmax = ps.getFloat("zmax", 1);
    if (!(zmin < zmax))
      failAt(rec.at, what + ": zmin " + fmtNum(zmin) + " must be below zmax " + fmtNum(zmax) + " (the cylinder would be empty)");
    q.zMin = ps.has("zmin") ? finite("zmin", zmin) : -1.0f;
    q.zMax = ps.has("zmax") ? finite("zmax", zmax) : 1.0f;
  }
  return q;
}

// A bilinear patch p(u, v) = (1-u)(1-v) p00 + u(1-v) p10 + (1-u)v p01 + uv p11
// is two triangles exactly when it is a parallelogram (twist
// T = p00 - p10 - p01 + p11 = 0). Otherwise it is cut into an n x n grid of
// cells, each two triangles with corners on the surface: in a cell the
// surface is bilinear with twist T / n^2 and lies within |T| / (4 n^2) of
// its triangles (the largest gap, at the cell's centre), so n is the
// smallest with |T| / (4 n^2) <= kBilinearTolerance x the patch's longest
// edge. |T| <= 2 x the longest edge, so n <= 23.
constexpr double kBilinearTolerance = 1e-3;

static int bilinearCells(Vec3f p00, Vec3f p10, Vec3f p01, Vec3f p11) {
  double twist = length((p00 + p11) - (p10 + p01));
  double edge = std::max({length(p10 - p00), length(p11 - p10), length(p01 - p11), length(p00 - p01), 1e-30f});
  if (twist <= 1e-5 * edge) return 1;
  return std::max(1, int(std::ceil(std::sqrt(twist / (4.0 * kBilinearTolerance * edge)))));
}

static void tessellateBilinear(const std::vector<Vec3f>& P, const std::vector<uint32_t>& idx, const Loc& at, Geometry& g) {
  uint64_t triangles = 0;
  for (size_t i = 0; i < idx.size(); i += 4) {
    uint64_t n = uint64_t(bilinearCells(P[idx[i]], P[idx[i + 1]], P[idx[i + 2]], P[idx[i + 3]]));
    triangles += 2 * n * n;
  }
  if (triangles > scene::limits::kMaxPbrtTriangles)
    failAt(at, "Shape \"bilinearmesh\": its curved patches make " + std::to_string(triangles) +
                   " triangles, more than tdpm's limit of " + std::to_string(scene::limits::kMaxPbrtTriangles));
  const bool withUv = !g.uv.empty();
  for (size_t i = 0; i < idx.size(); i += 4) {
    const uint32_t c[4] = {idx[i], idx[i + 1], idx[i + 2], idx[i + 3]};  // p00, p10, p01, p11
    int n = bilinearCells(P[c[0]], P[c[1]], P[c[2]], P[c[3]]);
    if (n == 1) {
      g.indices.insert(g.indices.end(), {c[0], c[1], c[3], c[0], c[3], c[2]});
      continue;
    }
    // (n+1)^2 new vertices on the surface, row v = j / n, column u = k / n.
    uint32_t base = uint32_t(g.vertices.size());
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        float u = float(k) / float(n), v = float(j) / float(n);
        float w[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
        g.vertices.push_back(P[c[0]] * w[0] + P[c[1]] * w[1] + P[c[2]] * w[2] + P[c[3]] * w[3]);
        if (withUv) {
          Vec2f t{0, 0};
          for (int q = 0; q < 4; ++q) t = {t.x + w[q] * g.uv[c[q]].x, t.y + w[q] * g.uv[c[q]].y};
          g.uv.push_back(t);
        }
      }
    auto at2 = [&](int j, int k) { return base + uint32_t(j * (n + 1) + k); };
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)  // the corner patch's split: (00, 10, 11), (00, 11, 01)
        g.indices.insert(g.indices.end(), {at2(j, k), at2(j, k + 1), at2(j + 1, k + 1), at2(j, k), at2(j + 1, k + 1), at2(j + 1, k)});
  }
}

// `inputs` collects the files read (PLY meshes).
static Geometry makeGeometry(const ShapeRecord& rec, const std::function<void(const std::string&)>& note, const std::string& mainDir,
                             std::vector<std::string>& inputs) {
  const ParamSet& ps = rec.params;
  Geometry g;
  if (rec.type == "sphere") {
    g.sphere = true;
    double r = ps.getFloat("radius", 1);
    if (!(r > 0)) failAt(rec.at, "Shape \"sphere\": radius must be positive, got " + fmtNum(r));
    double zmin = ps.getFloat("zmin", -r), zmax = ps.getFloat("zmax", r), phimax = ps.getFloat("phimax", 360);
    if (zmin > -r || zmax < r || phimax < 360)
      failAt(rec.at, "Shape \"sphere\": partial spheres (zmin, zmax, phimax) are not supported");
    g.radius = float(r);
  } else if (rec.type == "disk" || rec.type == "cylinder") {
    g.quadric = readQuadric(rec);
  } else if (rec.type == "trianglemesh" || rec.type == "bilinearmesh") {
    bool bilinear = rec.type == "bilinearmesh";
    std::vector<Vec3f> P = readPoints(ps, "P", rec.at);
    std::vector<uint32_t> idx = readIndices(ps, P.size(), bilinear ? 4 : 3, bilinear ? "patch" : "triangle", rec.at);
    std::vector<double> uv = ps.getFloats(ps.has("uv") ? "uv" : "st");
    if (!uv.empty()) {
      if (uv.size() != 2 * P.size()) ps.fail(*ps.find(ps.has("uv") ? "uv" : "st"), "expected 2 numbers per point");
      for (size_t i = 0; i < P.size(); ++i) g.uv.push_back({float(uv[2 * i]), float(uv[2 * i + 1])});
    } else if (bilinear && P.size() == 4 && idx.size() == 4) {
      const Vec2f corner[4] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}};  // pbrt's default (u, v) of p00, p10, p01, p11
      g.uv.assign(4, Vec2f{});
      for (size_t k = 0; k < 4; ++k) g.uv[idx[k]] = corner[k];
    }
    if (!bilinear && ps.has("N")) {
      // pbrt-v4 refuses a count that is not one normal per point; so does tdpm.
      const Param* np = ps.find("N");
      if (np->type != "normal" && np->type != "normal3") ps.fail(*np, "expected type normal");
      std::vector<double> N = ps.getFloats("N");
      if (N.size() != 3 * P.size())
        ps.fail(*np, "expected 3 numbers per point (" + std::to_string(3 * P.size()) + "), got " + std::to_string(N.size()));
      for (size_t i = 0; i < N.size(); i += 3) g.normals.push_back({float(N[i]), float(N[i + 1]), float(N[i + 2])});
    }
    for (const char* q : {"N", "S", "faceIndices"})
      if (ps.has(q) && !(q[0] == 'N' && !bilinear)) {
        ps.markUsed(q);
        note(std::string("Shape \"") + rec.type + "\": \"" + q + "\" ignored (tdpm shades " +
             (q[0] == 'N' ? "its tessellated patches with their geometric normals)" : "without shading tangents / face indices)"));
      }
    g.vertices = P;
    if (!bilinear) {
      g.indices = idx;
    } else {
      tessellateBilinear(P, idx, rec.at, g);
    }
  } else if (rec.type == "plymesh") {
    std::string file = ps.getString("filename", "");
    if (file.empty()) failAt(rec.at, "Shape \"plymesh\": missing parameter \"string filename\"");
    if (ps.has("displacement")) failAt(rec.at, "Shape \"plymesh\": displacement is not supported");
    ps.markUsed("edgelength");
    PlyMesh ply;
    try {
      std::string path = resolvePath(file, rec.at.file, mainDir);
      ply = readPly(path);
      inputs.push_back(path);
    } catch (const Error& e) {
      failAt(rec.at, std::string("Shape \"plymesh\": ") + e.what());
    }
    // One note for all of them (nx, ny, nz is one normal, not three notes).
    if (!ply.ignoredProperties.empty()) {
      std::string list;
      for (const std::string& q : ply.ignoredProperties) list += (list.empty() ? "\"" : ", \"") + q + "\"";
      note(std::string("Shape \"plymesh\": vertex ") + (ply.ignoredProperties.size() > 1 ? "properties " : "property ") + list +
           " ignored");
    }
    g.vertices = std::move(ply.vertices);
    g.uv = std::move(ply.uvs);
    g.normals = std::move(ply.normals);
    g.indices = std::move(ply.triangles);
    addQuads(g.vertices, ply.quads, rec.at, "Shape \"plymesh\" \"" + file + "\"", &g.indices);
  } else if (rec.type == "loopsubdiv") {
    g.vertices = readPoints(ps, "P", rec.at);
    g.indices = readIndices(ps, g.vertices.size(), 3, "triangle", rec.at);
    g.loopLevels = readLoopLevels(ps, g.indices.size() / 3, rec.at);
    std::string problem = scene::loopTopologyProblem(g.indices, g.vertices.size());
    if (!problem.empty()) failAt(rec.at, "Shape \"loopsubdiv\": " + problem);
    note("Shape \"loopsubdiv\": shaded with the refined triangles' geometric normals, not pbrt's limit-surface normals");
  } else {
    failAt(rec.at, "Shape \"" + rec.type + "\" is not supported (sphere, disk, cylinder, trianglemesh, bilinearmesh, plymesh, loopsubdiv)");
  }
  ps.checkAllUsed();
  return g;
}

Importer::MotionPlan Importer::planMotion(const Mat ctm[2], const Loc& at, const std::string& what) const {
  MotionPlan plan;
  Mat W = mirror_ ? mirrorX() : Mat();
  if (ctm[0] == ctm[1]) {
    plan.still = W * ctm[0];
    return plan;
  }
  // pbrt splits each transform into T R S and interpolates T and S
  // linearly and R by slerp between TransformTimes; tdpm's keyframes do the
  // same, so the two poses become two keyframes (clipped to the shutter).
  std::optional<Pose> p[2];
  for (int i = 0; i < 2; ++i) {
    p[i] = decompose(ctm[i]);
    std::string degenerate = scaleProblem(ctm[i]);
    if (!degenerate.empty())
      failAt(at, what + ": its " + (i ? "EndTime" : "StartTime") + " transform is unusable: " + degenerate);
    if (!p[i] || ctm[i].det3() < 0)
      failAt(at, what + ": its " + (i ? "EndTime" : "StartTime") +
                     " transform has shear, a scale along rotated axes or a mirror; pbrt would interpolate its polar "
                     "decomposition, which tdpm's keyframes cannot express");
  }
  float t0 = transformStart_, t1 = transformEnd_;
  auto poseAt = [&](float t) {
    float u = std::clamp((t - t0) / (t1 - t0), 0.0f, 1.0f);
    Pose q;
    q.translate = lerp(p[0]->translate, p[1]->translate, u);
    q.rotate = slerp(p[0]->rotate, p[1]->rotate, u);
    q.scale = lerp(p[0]->scale, p[1]->scale, u);
    return q;
  };
  auto toMat = [](const Pose& q) {
    Affine3f a = Affine3f::fromTRS(q.translate, q.rotate, q.scale);
    Mat m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 4; ++j) m.m[i][j] = a.m[i][j];
    return m;
  };
  float a = std::max(t0, shutterOpen_), b = std::min(t1, shutterClose_);
  if (!(a < b)) {
    // The shutter sees one pose: before the start, after the end, or an instant.
    if (t1 <= shutterOpen_) plan.still = W * ctm[1];
    else if (t0 >= shutterClose_) plan.still = W * ctm[0];
    else plan.still = W * toMat(poseAt(a));
    return plan;
  }
  plan.moving = true;
  for (float t : {a, b}) {
    Pose q = poseAt(t);
    if (mirror_) q = mirrorPose(q);
    scene::TransformDesc d;
    d.translate = q.translate;
    d.rotate = canonicalRotation(q.rotate);
    d.scale = q.scale;
    plan.keys.times.push_back(t);
    plan.keys.poses.push_back(d);
  }
  return plan;
}

static bool nearlyUniform(Vec3f s) {
  float a = std::fabs(s.x);
  return std::fabs(std::fabs(s.y) - a) <= 1e-5f * a && std::fabs(std::fabs(s.z) - a) <= 1e-5f * a;
}

void Importer::emitShape(const ShapeRecord& rec, const Mat ctm[2], const Loc& instanceAt) {
  if (rec.area && rec.type == "disk") return emitRoundLight(rec, ctm);  // an emitter only: no Geometry
  Geometry g = makeGeometry(rec, [&](const std::string& w) { note(rec.at, w); }, mainDir, result.inputFiles);
  countTriangles(g.indices.size() / 3, instanceAt.file.empty() ? rec.at : instanceAt,
                 instanceAt.file.empty() ? "Shape \"" + rec.type + "\"" : "ObjectInstance (Shape \"" + rec.type + "\" at " + rec.at.str() + ")");
  const MaterialSlot& mat = materials_[size_t(rec.material)];
  if (rec.area) {
    if (g.quadric)
      failAt(rec.at, "Shape \"" + rec.type + "\" with an AreaLightSource is not supported (emitters: sphere, disk, triangle meshes)");
    if (g.sphere) return emitRoundLight(rec, ctm);
    if (g.loopLevels >= 0) {
      scene::LoopMesh m = scene::loopSubdivide(g.vertices, g.indices, g.loopLevels, scene::limits::kMaxSubdividedTriangles);
      emitAreaLight(rec, m.vertices, m.indices, ctm);
    } else {
      emitAreaLight(rec, g.vertices, g.indices, ctm);
    }
    return;
  }
  // pbrt's "interface" material: no surface. A boundary between two media
  // is kept (an Interface object); without media it is dropped (invisible).
  if (mat.interface && rec.mediumInside == rec.mediumOutside) return;
  scene::ObjectDesc o;
  o.name = "Shape \"" + rec.type + "\" (" + rec.at.str() + (instanceAt.file.empty() ? "" : ", instance at " + instanceAt.str()) + ")";
  MotionPlan plan = planMotion(ctm, rec.at, "Shape \"" + rec.type + "\"");
  if (g.sphere) {
    o.shape.type = scene::ShapeDesc::Type::Sphere;
    o.shape.radius = g.radius;
    if (!plan.moving) {
      std::string degenerate = scaleProblem(plan.still);
      if (!degenerate.empty()) failAt(rec.at, "Shape \"sphere\": its transform is unusable: " + degenerate);
      std::optional<Pose> p = decompose(plan.still);
      if (!p || !nearlyUniform(p->scale))
        failAt(rec.at, "Shape \"sphere\" under a non-uniform scale or shear (an ellipsoid) is not supported");
      o.placement.translate = p->translate;
      o.placement.rotate = canonicalRotation(p->rotate);
      o.placement.scale = p->scale;
    } else {
      for (const auto& k : plan.keys.poses)
        if (!nearlyUniform(k.scale)) failAt(rec.at, "Shape \"sphere\" under a non-uniform scale (an ellipsoid) is not supported");
      o.motion = plan.keys;
    }
    // pbrt flips an analytic shape's normal when its transform swaps
    // handedness (so that it is cross(dp/du, dp/dv) in world space), and
    // again for ReverseOrientation; tdpm's sphere normal is always outward.
    // (tdpm's own x mirror is not in ctm: a mirror keeps sides.)
    o.shape.reverseOrientation = rec.reverseOrientation != (ctm[0].det3() < 0);
  } else if (g.quadric) {
    o.shape = *g.quadric;
    if (!plan.moving) {
      std::string degenerate = scaleProblem(plan.still);
      if (!degenerate.empty()) failAt(rec.at, "Shape \"" + rec.type + "\": its transform is unusable: " + degenerate);
      std::optional<Pose> p = decompose(plan.still);
      if (!p) failAt(rec.at, "Shape \"" + rec.type + "\" under shear or a scale along rotated axes is not supported (tdpm's placements are translate x rotate x scale)");
      o.placement.translate = p->translate;
      o.placement.rotate = canonicalRotation(p->rotate);
      o.placement.scale = p->scale;
    } else {
      o.motion = plan.keys;
    }
    o.shape.reverseOrientation = rec.reverseOrientation != (ctm[0].det3() < 0);  // as for the sphere
  } else {
    o.shape.type = scene::ShapeDesc::Type::Mesh;
    // A triangle's normal: (p1 - p0) x (p2 - p0), transformed as a normal
    // (the winding is kept through mirrors below), then ReverseOrientation.
    o.shape.reverseOrientation = rec.reverseOrientation;
    o.shape.indices = g.indices;
    // With shading normals (N, nx ny nz) pbrt turns each triangle's normal to
    // them and ignores ReverseOrientation: the windings are turned here
    // (before the bake, which keeps the agreement), so sides (glass, media)
    // are pbrt's and the renderer's "the geometric normal decides" holds.
    const bool smooth = !g.normals.empty() && g.loopLevels < 0;
    if (smooth) {
      orientToNormals(g.normals, g.vertices, &o.shape.indices);
      o.shape.reverseOrientation = false;
    }
    o.shape.loopLevels = g.loopLevels;  // placements are affine: refining after baking them is exact
    if (!plan.moving) {
      // Bake the placement into the vertices (any affine map is exact). A
      // mirroring map flips the winding; swap it back so the face normal
      // keeps pbrt's orientation (which transforms normals, not windings).
      for (Vec3f v : g.vertices) o.shape.vertices.push_back(plan.still.point(v));
      if (plan.still.det3() < 0)
        for (size_t i = 0; i < o.shape.indices.size(); i += 3) std::swap(o.shape.indices[i + 1], o.shape.indices[i + 2]);
    } else {
      o.shape.vertices = g.vertices;
      o.motion = plan.keys;
    }
    for (Vec3f v : o.shape.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        failAt(rec.at, "Shape \"" + rec.type + "\": a vertex is not finite after its transform");
    // (u, v) per corner, after any winding swap (per-vertex values follow
    // their vertex); loopsubdiv has none (its triangles are new).
    if (g.uv.size() == g.vertices.size() && g.loopLevels < 0)
      for (uint32_t i : o.shape.indices) o.shape.uvs.push_back(g.uv[i]);
    // Shading normals per corner likewise, baked as normals (inverse
    // transpose) with the vertices; a moving mesh keeps them in object space.
    if (smooth) {
      std::vector<Vec3f> N = g.normals;
      if (!plan.moving)
        for (Vec3f& n : N) n = plan.still.normal(n);
      o.shape.normals.reserve(o.shape.indices.size());
      for (uint32_t i : o.shape.indices) {
        if (!std::isfinite(N[i].x) || !std::isfinite(N[i].y) || !std::isfinite(N[i].z))
          failAt(rec.at, "Shape \"" + rec.type + "\": a normal is not finite after its transform");
        o.shape.normals.push_back(N[i]);
      }
    }
  }
  o.material = mat.interface ? interfaceMaterialIndex() : materialIndex(rec.material);
  result.scene.objects.push_back(std::move(o));
  objectAt_.push_back(rec.at);
  objectMedia(rec, result.scene.objects.size() - 1);
}

// pbrt's DiffuseAreaLight radiance: L x scale, or pbrt-v4's "power" (W)
// spread over the area and sides: L = power / (pi A sides).
Rgb Importer::areaLightL(const ShapeRecord& rec, double area, bool twoSided) {
  const ParamSet& ps = rec.area->params;
  Rgb L = nonNegative(ps, "L", color(ps, "L", Rgb(1.0f))) * lightScale(ps);
  double power = ps.has("power") ? ps.getFloat("power", -1) : -1;
  if (power > 0) L = L * float(power / (kPiD * area * (twoSided ? 2 : 1)));
  if (ps.has("filename")) failAt(rec.area->at, "AreaLightSource: an image emitter (filename) is not supported");
  noteLightSamples(ps, rec.area->at, "AreaLightSource");
  ps.checkAllUsed();
  return L;
}

void Importer::pushAreaLight(const ShapeRecord& rec, scene::LightDesc l) {
  const MaterialSlot& mat = materials_[size_t(rec.material)];
  // An emitter sends its light into the medium on its emitting side, pbrt's
  // outside (the side its normal faces, which is the side that emits).
  if (rec.mediumInside != rec.mediumOutside && l.twoSided)
    failAt(rec.at, l.name + ": a two-sided emitter between two media (MediumInterface at " + rec.mediumAt.str() +
                       ") is not supported: tdpm's lights emit into one medium");
  lightMedium(rec.mediumOutside, rec.mediumAt, result.scene.lights.size(), l.name);
  bool black = mat.interface || (mat.desc.type == scene::MaterialDesc::Type::Diffuse && mat.desc.albedo.color.isBlack());
  if (!black) note(rec.at, l.name + ": tdpm's area lights do not reflect light; the emitter's material is ignored");
  result.scene.lights.push_back(std::move(l));
  lightAt_.push_back(rec.area->at);
}

// A sphere or a disk with an AreaLightSource. pbrt's disk lies in its z =
// height plane facing +z; tdpm's in its local x-z plane emitting toward -y,
// so a rotation by -90 degrees about x (taking -y to +z) goes in between.
// pbrt flips either's normal when ReverseOrientation and a handedness-
// swapping transform disagree.
void Importer::emitRoundLight(const ShapeRecord& rec, const Mat ctm[2]) {
  const ParamSet& ps = rec.params;
  bool disk = rec.type == "disk";
  const std::string what = "AreaLightSource (" + rec.area->at.str() + ") on Shape \"" + rec.type + "\"";
  double r = ps.getFloat("radius", 1);
  if (!(r > 0)) failAt(rec.at, "Shape \"" + rec.type + "\": radius must be positive, got " + fmtNum(r));
  Mat local;
  if (disk) {
    double inner = ps.getFloat("innerradius", 0), phimax = ps.getFloat("phimax", 360), h = ps.getFloat("height", 0);
    if (inner != 0 || phimax < 360) failAt(rec.at, "Shape \"disk\": an annulus or a partial disk (innerradius, phimax) is not supported as an emitter");
    local = Mat::translate(0, 0, h) * Mat::rotate(-90, 1, 0, 0);
  } else {
    double zmin = ps.getFloat("zmin", -r), zmax = ps.getFloat("zmax", r), phimax = ps.getFloat("phimax", 360);
    if (zmin > -r || zmax < r || phimax < 360)
      failAt(rec.at, "Shape \"sphere\": partial spheres (zmin, zmax, phimax) are not supported");
  }
  ps.checkAllUsed();
  bool twoSided = rec.area->params.getBool("twosided", false);
  Mat placed[2] = {ctm[0] * local, ctm[1] * local};
  MotionPlan plan = planMotion(placed, rec.at, what);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.areaShape = disk ? scene::LightDesc::AreaShape::Disk : scene::LightDesc::AreaShape::Sphere;
  l.name = what;
  l.radius = float(r);
  l.twoSided = twoSided;
  l.reverseOrientation = rec.reverseOrientation != (ctm[0].det3() < 0);
  auto round = [&](Vec3f s) {
    float a = std::fabs(s.x);
    return disk ? std::fabs(std::fabs(s.z) - a) <= 1e-5f * a : nearlyUniform(s);
  };
  const char* shapeWord = disk ? "an ellipse" : "an ellipsoid";
  Vec3f scale0;
  if (!plan.moving) {
    std::string degenerate = scaleProblem(plan.still);
    if (!degenerate.empty()) failAt(rec.at, what + ": its transform is unusable: " + degenerate);
    std::optional<Pose> p = decompose(plan.still);
    if (!p || !round(p->scale)) failAt(rec.at, what + " under a non-uniform scale or shear (" + shapeWord + ") is not supported");
    l.placement.translate = p->translate;
    l.placement.rotate = canonicalRotation(p->rotate);
    l.placement.scale = p->scale;
    scale0 = p->scale;
  } else {
    for (const auto& k : plan.keys.poses)
      if (!round(k.scale)) failAt(rec.at, what + " under a non-uniform scale (" + shapeWord + ") is not supported");
    l.motion = plan.keys;
    scale0 = plan.keys.poses[0].scale;
  }
  float s = std::fabs(scale0.x);
  double area = disk ? kPiD * r * r * s * s : 4.0 * kPiD * r * r * s * s;  // at the first pose (pbrt's Area())
  Rgb L = areaLightL(rec, area, twoSided);
  l.power = L * float(kPiD * area * (twoSided ? 2 : 1));  // Lambertian: power = L pi A sides
  pushAreaLight(rec, std::move(l));
}

// Flips the windings that disagree with the triangle mesh's shading normals
// N (object space); false (nothing done) when it has none.
void orientToNormals(const std::vector<Vec3f>& N, const std::vector<Vec3f>& verts, std::vector<uint32_t>* indices) {
  std::vector<uint32_t>& idx = *indices;
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    Vec3f g = cross(verts[idx[t + 1]] - verts[idx[t]], verts[idx[t + 2]] - verts[idx[t]]);
    if (dot(g, N[idx[t]] + N[idx[t + 1]] + N[idx[t + 2]]) < 0) std::swap(idx[t + 1], idx[t + 2]);
  }
}

bool facesShadingNormals(const ShapeRecord& rec, const std::vector<Vec3f>& verts, std::vector<uint32_t>* indices) {
  if (rec.type != "trianglemesh" || !rec.params.has("N")) return false;
  std::vector<double> N = rec.params.getFloats("N");
  if (N.size() != 3 * verts.size()) return false;  // refused by makeGeometry before this is reached
  std::vector<Vec3f> n(verts.size());
  for (size_t i = 0; i < n.size(); ++i) n[i] = {float(N[3 * i]), float(N[3 * i + 1]), float(N[3 * i + 2])};
  orientToNormals(n, verts, indices);
  return true;
}

// pbrt turns a triangle with shading normals N to face them (and then
// ignores ReverseOrientation): a one-sided mesh emitter's windings are
// flipped where they disagree with the sum of their vertices' N (object
// space; the bake keeps the agreement, normals transforming alike).
static void orientByShadingNormals(const ShapeRecord& rec, const std::vector<Vec3f>& verts, scene::LightDesc* l) {
  if (facesShadingNormals(rec, verts, &l->mesh.indices)) l->reverseOrientation = false;
}

// A triangle mesh with an AreaLightSource: a rectangle light when it is one
// still rectangle of two triangles facing the same way (as before), else a
// mesh emitter (any triangles, sampled by area).
void Importer::emitAreaLight(const ShapeRecord& rec, const std::vector<Vec3f>& verts, const std::vector<uint32_t>& idx,
                             const Mat ctm[2]) {
  const ParamSet& ps = rec.area->params;
  const std::string what = "AreaLightSource (" + rec.area->at.str() + ") on Shape \"" + rec.type + "\"";
  bool twoSided = ps.getBool("twosided", false);
  MotionPlan plan = planMotion(ctm, rec.at, what);
  scene::LightDesc l;
  l.type = scene::LightDesc::Type::Area;
  l.name = what;
  l.twoSided = twoSided;
  l.reverseOrientation = rec.reverseOrientation;  // the winding already follows pbrt's handedness rule
  const Mat& M = plan.still;
  // World (first pose) area, for "power" and the light's watts.
  Mat M0 = plan.moving ? Mat() : M;
  double area = 0;
  for (size_t t = 0; t + 2 < idx.size(); t += 3) {
    Vec3f p0 = verts[idx[t]], p1 = verts[idx[t + 1]], p2 = verts[idx[t + 2]];
    if (plan.moving) {
      Affine3f a = plan.keys.poses[0].matrix();
      p0 = a.point(p0); p1 = a.point(p1); p2 = a.point(p2);
    } else {
      p0 = M0.point(p0); p1 = M0.point(p1); p2 = M0.point(p2);
    }
    area += 0.5 * double(length(cross(p1 - p0, p2 - p0)));
  }
  if (!(area > 1e-30)) failAt(rec.at, what + ": the emitter has zero area");
  std::vector<uint32_t> corners(idx.begin(), idx.end());
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  bool rectangle = false;
  if (!plan.moving && idx.size() == 6 && corners.size() == 4) {
    Vec3f P[4];
    for (int i = 0; i < 4; ++i) P[i] = M.point(verts[corners[size_t(i)]]);
    int far = 1;
    for (int i = 2; i < 4; ++i)
      if (length(P[i] - P[0]) > length(P[far] - P[0])) far = i;
    int a = far == 1 ? 2 : 1, b = far == 3 ? 2 : 3;
    Vec3f e1 = P[a] - P[0], e2 = P[b] - P[0];
    float l1 = length(e1), l2 = length(e2);
    Vec3f tri[2];
    for (int t = 0; t < 2; ++t) {
      Vec3f p0 = verts[idx[size_t(3 * t)]], p1 = verts[idx[size_t(3 * t + 1)]], p2 = verts[idx[size_t(3 * t + 2)]];
      tri[t] = M.normal(cross(p1 - p0, p2 - p0));  // pbrt's normal: the object-space one, transformed as a normal
    }
    float rectArea = l1 * l2;
    rectangle = l1 > 0 && l2 > 0 && std::fabs(dot(e1, e2)) <= 1e-4f * l1 * l2 &&
                length(P[0] + e1 + e2 - P[far]) <= 1e-4f * (l1 + l2) && std::fabs(float(area) - rectArea) <= 1e-4f * rectArea &&
                dot(tri[0], tri[1]) > 0;
    if (rectangle) {
      Vec3f n = normalize(tri[0]);
      if (rec.type == "trianglemesh" && rec.params.has("N")) {
        // Faces its shading normals, as orientByShadingNormals below.
        std::vector<double> N = rec.params.getFloats("N");
        Vec3f sum{0, 0, 0};
        for (size_t i = 0; i + 2 < N.size(); i += 3) sum += Vec3f{float(N[i]), float(N[i + 1]), float(N[i + 2])};
        if (dot(n, M.normal(sum)) < 0) n = -n;
        l.reverseOrientation = false;
      }
      Vec3f x = e1 / l1, y = -n, z = cross(x, y);
      double R[3][3] = {{x.x, y.x, z.x}, {x.y, y.y, z.y}, {x.z, y.z, z.z}};
      l.areaShape = scene::LightDesc::AreaShape::Rect;
      l.areaSize = {l1, l2};
      l.placement.translate = P[0] + (e1 + e2) * 0.5f;
      l.placement.rotate = canonicalRotation(quaternionFromMatrix(R));
      area = rectArea;
    }
  }
  if (!rectangle) {
    l.areaShape = scene::LightDesc::AreaShape::Mesh;
    l.mesh.type = scene::ShapeDesc::Type::Mesh;
    l.mesh.indices = idx;
    orientByShadingNormals(rec, verts, &l);
    if (!plan.moving) {
      // Baked like a plain mesh (emitShape): a mirroring map's winding swapped back.
      for (Vec3f v : verts) l.mesh.vertices.push_back(M.point(v));
      if (M.det3() < 0)
        for (size_t i = 0; i < l.mesh.indices.size(); i += 3) std::swap(l.mesh.indices[i + 1], l.mesh.indices[i + 2]);
    } else {
      l.mesh.vertices = verts;
      l.motion = plan.keys;
      for (const auto& k : plan.keys.poses) {
        Vec3f s0 = plan.keys.poses[0].scale;
        Vec3f q{k.scale.x / s0.x, k.scale.y / s0.y, k.scale.z / s0.z};
        if (!nearlyUniform(q)) failAt(rec.at, what + ": a moving emissive mesh may change its size only uniformly");
      }
    }
    for (Vec3f v : l.mesh.vertices)
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        failAt(rec.at, what + ": a vertex is not finite after its transform");
  }
  Rgb L = areaLightL(rec, area, twoSided);
  l.power = L * float(kPiD * area * (twoSided ? 2 : 1));  // Lambertian: power = L pi A sides
  pushAreaLight(rec, std::move(l));
}

}  // namespace tdpm::pbrt::detail
