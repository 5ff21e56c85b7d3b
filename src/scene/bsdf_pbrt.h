// scene/bsdf_pbrt.h — the BSDFs of pbrt's materials (Material::Type
// Conductor .. CoatedConductor), called from scene/bsdf.cpp's switch; local
// shading frame, z = normal, wo and wi as in scene/bsdf.h. The microfacet
// model is pbrt-v4's: isotropic Trowbridge-Reitz (GGX) with height-
// correlated Smith masking, sampled by visible normals (Heitz 2018).
#pragma once
#include "scene/bsdf.h"

namespace tdpm {

// GGX alpha below which pbrt-v4 treats a microfacet surface as smooth.
constexpr float kSmoothAlpha = 1e-3f;

Rgb pbrtBsdfEval(const ShadingContext& c, Vec3f wo, Vec3f wi);
float pbrtBsdfPdf(const ShadingContext& c, Vec3f wo, Vec3f wi);
bool pbrtBsdfSample(const ShadingContext& c, Vec2f u, float uLobe, Transport mode, BsdfSample& out);

// Unpolarised Fresnel reflectance of a conductor with complex IOR
// eta + i k (relative to the incident medium); cosI in [0, 1].
float fresnelConductor(float cosI, float eta, float k);
// pbrt-v4's FrDielectric: cosI may be negative (incidence from inside,
// eta = eta_inside / eta_outside is then inverted).
float fresnelDielectricSigned(float cosI, float eta);
// Cosine-weighted hemispherical average of the reflectance seen from
// inside a coating of index eta (>= 1): 1 - (1 - F_ext) / eta^2.
float coatInternalReflectance(float eta);

// The GGX pieces the tests' reference random walks also use.
namespace ggx {
float D(Vec3f wm, float alpha);
float G(Vec3f wo, Vec3f wi, float alpha);
float visiblePdf(Vec3f w, Vec3f wm, float alpha);  // D_w(wm) = G1(w) / |cos w| D(wm) |w . wm|
Vec3f sampleVisible(Vec3f w, Vec2f u, float alpha);
}  // namespace ggx

}  // namespace tdpm
