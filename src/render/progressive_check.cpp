// render/progressive_check.cpp — checkProgressiveState
// (render/progressive_check.h): the fields of a resumed state against their
// ranges, against each other and against the layers.
#include "render/progressive_check.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

#include "core/error.h"
#include "photon/tracer.h"
#include "render/progressive_io.h"
#include "scene/limits.h"

namespace tdpm {

namespace {

const char* const kLayerNames[] = {"sum.R", "sum.G", "sum.B", "sumsq.R", "sumsq.G", "sumsq.B", "spp"};

// Float counts are exact integers up to here.
constexpr double kExactFloat = 16777216.0;  // 2^24

std::string g(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// The spp layer of a pixel that took `m` samples in each of `passes`
// passes: the float sum addPass forms (render/progressive.cpp).
double floatCount(int passes, float m) {
  float c = 0;
  for (int i = 0; i < passes; ++i) c += m;
  return double(c);
}

struct Checker {
  const ProgressiveState& s;
  const std::string& path;

  Error bad(const std::string& what) const { return Error("damaged progressive state: " + path + ": " + what); }

  // A scalar of the state by its name on disk (render/progressive_io.h),
  // finite, in [lo, hi] (lo excluded when `open`).
  double inRange(const ProgressiveScalar& sc, double lo, double hi, bool open, const std::string& why) const {
    const double v = *sc.value;
    const std::string name = "tdpm/progressive/scalar/" + sc.name;
    if (!std::isfinite(v)) throw bad(name + " is " + g(v) + ", not finite");
    if (v < lo || v > hi || (open && v == lo)) throw bad(name + " is " + g(v) + ", " + why);
    return v;
  }
};

// The most paths the tracer emits in one pass for `wanted` stored photons
// (photon/tracer.cpp: at most kMaxPathsPerPhoton per photon, whole batches, at least one).
double pathCap(double wanted) {
  double batches = std::ceil(photon::kMaxPathsPerPhoton * wanted / double(photon::kPathsPerBatch));
  return std::max(1.0, batches) * double(photon::kPathsPerBatch);
}

double checkPaths(const Checker& c, const ProgressiveScalar& sc, double wanted, const std::string& flag) {
  const double cap = pathCap(wanted);
  double v = c.inRange(sc, 0, wanted > 0 ? cap : 0, false,
                       wanted > 0 ? "outside [0, " + g(cap) + "]: " + flag + " " + g(wanted) +
                                        " emits at most that many paths per pass"
                                  : std::string("but this render traces no such photons (") + flag + "), so it must be 0");
  if (std::fmod(v, double(photon::kPathsPerBatch)) != 0)
    throw c.bad("tdpm/progressive/scalar/" + sc.name + " is " + g(v) + ", not a whole number of " +
                std::to_string(photon::kPathsPerBatch) + "-path batches");
  return v;
}

void checkLayers(const Checker& c, const RenderOptions& opt, int width, int height) {
  const ProgressiveState& s = c.s;
  const size_t n = size_t(width) * size_t(height);
  std::set<std::string> known(std::begin(kLayerNames), std::end(kLayerNames));
  for (const auto& kv : s.layers)
    if (!known.count(kv.first)) throw c.bad("layer progressive." + kv.first + " is not one a progressive render writes");
  const double passes = double(s.passesDone);
  const bool extra = opt.passExtraSamples > 0 && opt.passSampleCap > 1;
  const double lo = passes * double(opt.spp), hi = lo * double(extra ? opt.passSampleCap : 1);
  const bool exact = hi <= kExactFloat;
  // Above 2^24 the float layer rounds as it grows: the bounds are what the
  // pass loop's own float additions give (monotone in the per-pass count).
  const double loSum = exact ? lo : floatCount(s.passesDone, float(opt.spp));
  const double hiSum = exact ? hi : floatCount(s.passesDone, float(double(opt.spp) * (extra ? opt.passSampleCap : 1)));
  auto where = [&](size_t i) {
    return " at pixel (" + std::to_string(i % size_t(width)) + ", " + std::to_string(i / size_t(width)) + ")";
  };
  for (const char* name : kLayerNames) {
    auto it = s.layers.find(name);
    if (it == s.layers.end()) throw c.bad(std::string("layer progressive.") + name + " is missing");
    const std::vector<float>& l = it->second;
    if (l.size() != n)
      throw c.bad(std::string("layer progressive.") + name + " holds " + std::to_string(l.size()) + " pixels, not " +
                  std::to_string(n));
    const bool sq = std::string(name).compare(0, 6, "sumsq.") == 0, spp = std::string(name) == "spp";
    for (size_t i = 0; i < n; ++i) {
      const double v = double(l[i]);
      if (!std::isfinite(v)) throw c.bad(std::string("layer progressive.") + name + " is " + g(v) + where(i) + ", not finite");
      if (sq && v < 0) throw c.bad(std::string("layer progressive.") + name + " is " + g(v) + where(i) + ", a negative sum of squares");
      if (!spp) continue;
      // Pixel p takes the same m_p samples in every pass, spp <= m_p <= cap x spp
      // (render/sample_allocation.h): its count is passes x m_p.
      const bool ok = v >= loSum && v <= hiSum && (!exact || std::fmod(v, passes) == 0);
      if (!ok)
        throw c.bad("layer progressive.spp is " + g(v) + where(i) + ", not " + g(passes) + " passes x " +
                    (extra ? std::to_string(opt.spp) + " to " + g(double(opt.spp) * opt.passSampleCap)
                           : std::to_string(opt.spp)) +
                    " samples per pass (tdpm/progressive/passes and the layer disagree)");
    }
  }
}

}  // namespace

int maxProgressivePasses() { return int(scene::limits::kPasses.hi); }

void checkProgressiveState(const ProgressiveState& s, const RenderOptions& opt, int width, int height,
                           const std::string& path) {
  const Checker c{s, path};
  if (s.passesDone < 1 || s.passesDone > maxProgressivePasses())
    throw c.bad("tdpm/progressive/passes is " + std::to_string(s.passesDone) + ", outside [1, " +
                std::to_string(maxProgressivePasses()) + "]");
  using R = ProgressiveScalarRole;
  const std::vector<ProgressiveScalar> scalars = progressiveScalars(s);
  if (!s.pilot.done) throw c.bad("tdpm/progressive/scalar/" + scalars[0].name + " is missing");
  auto named = [&](const std::string& name) -> const ProgressiveScalar& {
    for (const ProgressiveScalar& sc : scalars)
      if (sc.name == name) return sc;
    TDPM_ASSERT(false, "render/progressive_io.cpp has no scalar " + name);
    return scalars[0];
  };

  const double passes = double(s.passesDone);
  const bool wantGlobal = opt.visualizeGlobal || opt.gatherRays > 0;
  // Paths per pass of each map: within what its photon count may emit.
  double paths = 0, most = -1;
  const ProgressiveScalar* largest = nullptr;
  for (const ProgressiveScalar& sc : scalars) {
    if (sc.role != R::Paths) continue;
    const MapKindInfo& row = mapKindInfo(sc.kind);
    const bool traced = !row.onlyWhenGathered || wantGlobal;
    const size_t count = opt.*row.photons;
    const std::string why = !traced       ? std::string("--gather 0 without --global-direct")
                            : count > 0 ? opt.*row.photonsSource
                                        : std::string("its ") + row.name + " photons are 0";
    const double v = checkPaths(c, sc, traced ? double(count) : 0.0, why);
    paths += v;
    if (v > most) most = v, largest = &sc;
  }
  // Pass i traces paths [i p, (i + 1) p) (photon/tracer.h firstPath, 64 bits);
  // the passes this run may add must keep that in range.
  const double lastPass = std::max(passes + 1, double(opt.passes));
  if (lastPass * most > 0x1p62)
    throw c.bad("tdpm/progressive/scalar/" + largest->name + " is " + g(most) + ": " + g(lastPass) +
                " passes of it overflow the path index");
  const double emitted = c.inRange(named("photons.emitted"), 0, DBL_MAX, false, "negative");
  const double expected = passes * paths;
  if (std::fabs(emitted - expected) > 1e-12 * expected)
    throw c.bad("tdpm/progressive/scalar/photons.emitted is " + g(emitted) + ", not passes x paths per pass = " +
                g(passes) + " x " + g(paths) + " = " + g(expected));
  const double stored = c.inRange(named("photons.stored"), 0, DBL_MAX, false, "negative");
  if (std::floor(stored) != stored) throw c.bad("tdpm/progressive/scalar/photons.stored is " + g(stored) + ", not a count");
  if (emitted == 0 && stored > 0)
    throw c.bad("tdpm/progressive/scalar/photons.stored is " + g(stored) + ", but no photon path was emitted");
  c.inRange(named("seconds"), 0, DBL_MAX, false, "negative");
  // Pass 1's kernels from the pilot (render/progressive.cpp pilotKernel):
  // positive floats; every later pass scales them down.
  for (const ProgressiveScalar& sc : scalars) {
    if (sc.role == R::Kernel) c.inRange(sc, 0, FLT_MAX, true, "not a positive float");
    if (sc.role == R::Report) c.inRange(sc, 0, FLT_MAX, false, "not a float >= 0");
  }
  checkLayers(c, opt, width, height);
}

}  // namespace tdpm
