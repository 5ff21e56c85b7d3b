// render/animation.cpp — the photon timeline of an animation: its time
// grid, its segments (traced once, held for a sliding window of frames),
// the frame maps assembled from them, and the frame loop.
#include "render/animation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <tbb/task_arena.h>

#include "core/error.h"
#include "core/memory.h"
#include "core/rng.h"
#include "core/timer.h"
#include "photon/tracer.h"
#include "render/memory_budget.h"
#include "render/photon_map.h"
#include "render/animation_progressive.h"

namespace tdpm {

namespace {

// A piece of the timeline between two consecutive cut points of the grid
// (bins [lo, hi)): traced once, whichever frames use it.
struct Segment {
  int64_t lo = 0, hi = 0;
  PerMap<photon::PhotonStore> stores;  // by map kind
  size_t size() const {
    size_t n = 0;
    for (MapKind k : kAllMapKinds) n += stores[k].size();
    return n;
  }
};

// The grid's cut points that matter for frames [first, last]: the ends of
// every nearby frame's shutter and time map, clipped to the timeline.
// Frames more than 5 periods away cannot cut inside these frames' maps (a
// map spans S + 2P <= 3B + 2 bins), so the segments found here are the
// same as for the whole timeline and do not depend on the frame range.
std::vector<int64_t> cutPoints(const TimeGrid& g, int frames, int first, int last) {
  const int64_t end = int64_t(frames) * g.binsPerFrame;
  std::vector<int64_t> c{0, end};
  for (int i = std::max(0, first - 5); i <= std::min(frames - 1, last + 5); ++i)
    for (int64_t p : {g.mapLo(i), int64_t(i) * g.binsPerFrame, int64_t(i) * g.binsPerFrame + g.shutterBins, g.mapHi(i)})
      c.push_back(std::clamp<int64_t>(p, 0, end));
  std::sort(c.begin(), c.end());
  c.erase(std::unique(c.begin(), c.end()), c.end());
  return c;
}

bool inside(int64_t lo, int64_t hi, int64_t a, int64_t b) { return lo >= a && hi <= b; }

// The time-invariant photons of one block of frames (docs/animation.md
// section 7): traced once over the block's time [lo, hi) (bins, clipped to
// the timeline), energies Q = Phi (hi - lo) w / n over it, times uniform
// over it (the store's 256 bins span it). A frame spreads them over its own
// map's time with energies scaled to that length (frameMap).
struct SharedSet {
  int block = -1;
  int64_t lo = 0, hi = 0;
  photon::MotionBounds motion;  // swept bounds of what moves during [lo, hi)
  PerMap<photon::PhotonStore> stores;
  // Continuation: the block pass's paths that met motion, at their last
  // invariant vertex (a flat array per kind, freed with the block).
  PerMap<photon::KeptPaths> kept;
  size_t keptStates() const {
    size_t n = 0;
    for (MapKind k : kAllMapKinds) n += kept[k].states.size();
    return n;
  }
  size_t size() const {
    size_t n = 0;
    for (MapKind k : kAllMapKinds) n += stores[k].size();
    return n;
  }
};

// A shared photon's energy scaled to a part of its block's time (RGBE
// re-encoded: rounded to nearest, zero-mean error as the store's own).
uint32_t scaledEnergy(uint32_t rgbe, float factor) { return photon::encodeRgbe(photon::decodeRgbe(rgbe) * factor); }

// One of a frame's stores and where its photons go in it.
struct FrameStore {
  int64_t a = 0, b = 0;        // the segments inside grid bins [a, b) join it,
  int64_t base = 0, span = 0;  // re-binned onto its 256 bins over grid bins [base, base + span)
  // The shared set's photons: energy x sharedBins / (block length), its
  // place q of 256 in the block's time at store bin sharedOff + q sharedSpan / 256.
  int64_t sharedBins = 0, sharedOff = 0, sharedSpan = photon::kTimeBins;
};

// Photons of one kind of the segments inside grid bins [a, b) and of the
// shared set.
size_t photonsInside(const std::vector<const Segment*>& segments, const SharedSet* shared, MapKind kind, int64_t a,
                     int64_t b) {
  size_t n = shared ? shared->stores[kind].size() : 0;
  for (const Segment* s : segments)
    if (inside(s->lo, s->hi, a, b)) n += s->stores[kind].size();
  return n;
}

// What every frame map of a run is built with.
struct FrameMapSettings {
  int64_t timelineEnd = 0;  // bins
  bool spaceTime = false;   // surfaces: the 4D tree
  float kappa = 1.0f;
  photon::BeamBuildOptions beam;  // volume: the beam kernels, resolved for a frame's shutter
};

// The frame's photons of one kind into one store (FrameStore). Shared
// photons keep their place q of 256 in the block's time (uniform and
// independent of where they lie: the density in time of light that does
// not change), spread over the time they stand for in this store.
photon::PhotonStore frameStore(const std::vector<const Segment*>& segments, const SharedSet* shared, MapKind kind,
                               const TimeGrid& g, const FrameStore& f) {
  photon::PhotonStore out(float(double(f.base) * g.binWidth), float(double(f.base + f.span) * g.binWidth));
  out.reserve(photonsInside(segments, shared, kind, f.a, f.b));
  if (shared) {
    const photon::PhotonStore& st = shared->stores[kind];
    const float factor = float(double(f.sharedBins) / double(shared->hi - shared->lo));
    for (size_t p = 0; p < st.size(); ++p)
      out.addEncoded(st.xs()[p], st.ys()[p], st.zs()[p], scaledEnergy(st.energies()[p], factor), st.directions()[p],
                     st.flags()[p], uint8_t(f.sharedOff + st.timeBin(p) * f.sharedSpan / photon::kTimeBins));
  }
  for (const Segment* s : segments) {
    if (!inside(s->lo, s->hi, f.a, f.b)) continue;
    const photon::PhotonStore& st = s->stores[kind];
    const int64_t last = s->hi - s->lo - 1;
    for (size_t p = 0; p < st.size(); ++p) {
      // A time a rounding error past the segment's end stays in it.
      const int64_t bin = s->lo + std::min<int64_t>(st.timeBin(p), last);
      out.addEncoded(st.xs()[p], st.ys()[p], st.zs()[p], st.energies()[p], st.directions()[p], st.flags()[p],
                     uint8_t((bin - f.base) * photon::kTimeBins / f.span));
    }
  }
  return out;
}

// Frame i's map of one kind, from the segments inside its time map and the
// block's shared set (docs/animation.md sections 5 and 7). Surfaces: every
// photon of the time map, re-binned on the frame's 256 bins (an integer
// shift: same grid), and a 3D tree of its shutter's photons alone for the
// standard estimate. Volume (scenes with media): beam maps, their kernels
// built as a still render's (render/photon_map.h). Standard: one, over the
// shutter's photons alone (as the surfaces' standard store). Time: one over
// the time map's photons, the store's 256 bins stretched over exactly the
// time they cover, [c0, c1) (the map clipped to the timeline), because the
// beam estimate treats the store's ends as the photons' ends: it reflects
// the windows there and spreads a whole-shutter photon over all 256 bins;
// and a Standard one over the shutter's photons for the skip rule's
// standard form (the shutter's average, not the pads').
std::unique_ptr<PhotonMap> frameMap(const std::vector<const Segment*>& segments, const SharedSet* shared,
                                    MapKind kind, const TimeGrid& g, int frame, const FrameMapSettings& fs) {
  const int64_t lo = g.mapLo(frame), hi = g.mapHi(frame);
  const int64_t c0 = std::max<int64_t>(lo, 0), c1 = std::min(hi, fs.timelineEnd);
  const int64_t s0 = int64_t(frame) * g.binsPerFrame, s1 = s0 + g.shutterBins;
  const FrameStore own{s0, s1, s0, g.shutterBins, g.shutterBins};
  auto map = std::make_unique<PhotonMap>();
  map->ownPhotons = photonsInside(segments, shared, kind, s0, s1);
  if (kind == MapKind::Volume) {
    if (fs.beam.kind != photon::BeamBuildOptions::Kind::Time) {
      map->store = frameStore(segments, shared, kind, g, own);
      if (!map->store.empty()) map->beams = photon::VolumeBeamMap::build(map->store, fs.beam);
      return map;
    }
    map->separateStandard = true;
    map->store = frameStore(segments, shared, kind, g, FrameStore{lo, hi, c0, c1 - c0, c1 - c0});
    if (!map->store.empty()) map->beams = photon::VolumeBeamMap::build(map->store, fs.beam);
    map->store3 = frameStore(segments, shared, kind, g, own);
    photon::BeamBuildOptions standard = fs.beam;
    standard.kind = photon::BeamBuildOptions::Kind::Standard;
    if (!map->store3.empty()) map->beams3 = photon::VolumeBeamMap::build(map->store3, standard);
    return map;
  }
  map->separateStandard = true;
  map->store = frameStore(segments, shared, kind, g, FrameStore{lo, hi, lo, photon::kTimeBins, c1 - c0, c0 - lo, c1 - c0});
  photon::KdBuildOptions opt;
  opt.spaceTime = fs.spaceTime;
  opt.kappa = fs.kappa;
  map->tree = photon::KdTree::build(map->store, opt);
  map->store3 = frameStore(segments, shared, kind, g, own);
  map->tree3 = photon::KdTree::build(map->store3, {});
  return map;
}

}  // namespace

Shutter frameShutter(const scene::AnimationDesc& a, int frame) {
  return Shutter{float(a.frameOpen(frame)), float(a.frameClose(frame))};
}

TimeGrid makeTimeGrid(const scene::AnimationDesc& a, double reach) {
  reach = std::clamp(reach, 0.0, 1.0);
  const double share = a.shutterAngle / 360.0;  // of a frame period
  auto fits = [&](int64_t B, TimeGrid& g) {
    int64_t S = std::max<int64_t>(1, std::llround(double(B) * share));
    int64_t P = int64_t(std::ceil(reach * double(S))) + 1;
    if (S + 2 * P > photon::kTimeBins) return false;
    g.binsPerFrame = B;
    g.shutterBins = S;
    g.padBins = P;
    g.binWidth = 1.0 / (double(B) * a.fps);
    return true;
  };
  // fits(B) is monotone (S grows with B, and S + 2P with S): the largest B
  // that fits is found by bisection, not by counting down from 256 / share
  // (issue 27 item 2: ~9e10 steps for a 1e-6 degree shutter).
  const int64_t top = std::max<int64_t>(1, int64_t(std::min(std::floor(double(photon::kTimeBins) / share), 9e15)));
  TimeGrid best, g;
  int64_t lo = 1, hi = top;  // fits(lo) holds (S = 1); find the largest B in [lo, hi] that fits
  if (fits(hi, g)) lo = hi;
  while (hi - lo > 1) {
    int64_t mid = lo + (hi - lo) / 2;
    (fits(mid, g) ? lo : hi) = mid;
  }
  const int64_t B = lo;
  fits(B, best);
  // Prefer a B (down to half the largest) whose shutter is whole bins:
  // then the standard estimate's photons are exactly the shutter's. Every
  // B below the largest fits; the candidates are the b near m / share for
  // each whole shutter m, largest first (what a count down from B finds).
  const int64_t bLow = std::max<int64_t>(1, B / 2);
  auto whole = [&](int64_t b) { return std::fabs(double(b) * share - double(std::max<int64_t>(1, std::llround(double(b) * share)))) < 1e-6; };
  for (int64_t m = std::llround(double(B) * share); m >= 1 && double(m) >= double(bLow) * share - 1; --m) {
    int64_t b1 = std::min(B, int64_t(std::floor((double(m) + 1e-6) / share)) + 1);
    int64_t b0 = std::max(bLow, int64_t(std::ceil((double(m) - 1e-6) / share)) - 1);
    for (int64_t b = b1; b >= b0; --b)
      if (whole(b) && fits(b, g)) return g;
  }
  return best;
}

namespace {

void addWarning(AnimationStats& stats, const std::string& w) {
  if (!w.empty() && std::find(stats.warnings.begin(), stats.warnings.end(), w) == stats.warnings.end())
    stats.warnings.push_back(w);
}

// Memory: the window's segments (each frame's shutter and pads) and one
// frame's two copies of its maps, at --photons per shutter.
// With sharing, the block's shared set too (sharedScale frames' maps, held
// once and copied into each frame's maps).
void checkAnimationMemory(const Scene& scene, const RenderOptions& opt, const TimeGrid& grid, int window,
                          int windowFlag, bool photons, double sharedScale) {
  if (!photons) {
    checkMemoryBudget(scene, opt, tbb::this_task_arena::max_concurrency(), availableMemoryBytes());
    return;
  }
  RenderOptions held = opt;
  const double mapShare = double(grid.shutterBins + 2 * grid.padBins) / double(grid.shutterBins);
  double factor = double(window + 2) * mapShare + 1.0 + 3.0 * sharedScale * mapShare;
  // The budget's message names what multiplied the scene's counts.
  const std::string times = " per frame, held for a window of " + std::to_string(window) +
                            " frames at once (--window " + std::to_string(windowFlag) + ")";
  const PerMap<size_t> wanted = photonsWanted(opt);
  for (MapKind k : kAllMapKinds) {
    const MapKindInfo& row = mapKindInfo(k);
    held.*row.photons = size_t(double(wanted[k]) * factor);
    held.*row.photonsSource = opt.*row.photonsSource + " (" + std::to_string(opt.*row.photons) + times + ")";
  }
  checkMemoryBudget(scene, held, tbb::this_task_arena::max_concurrency(), availableMemoryBytes());
}

// The fixed-budget frame loop's photon side: the segments of the timeline,
// traced when a window of frames first needs them and held until no later
// frame of the run does, and the pilot rates that size their emission.
class SegmentTimeline {
 public:
  SegmentTimeline(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                  const AnimationOptions& ao, const TimeGrid& grid, const PerMap<size_t>& perShutter,
                  const Progress& framed, AnimationStats& stats)
      : scene_(scene), anim_(anim), opt_(opt), ao_(ao), grid_(grid), perShutter_(perShutter), framed_(framed),
        stats_(stats), cuts_(cutPoints(grid, anim.frames, ao.first, ao.last)) {}

  // Trace the segments frames [w0, w1] need that are not held yet.
  void traceWindow(int w0, int w1) {
    Timer timer;
    for (size_t k = 0; k + 1 < cuts_.size(); ++k) {
      int64_t lo = cuts_[k], hi = cuts_[k + 1];
      if (hi <= grid_.mapLo(w0) || lo >= grid_.mapHi(w1) || held_.count(lo)) continue;
      bool used = false;
      for (int i = w0; i <= w1 && !used; ++i) used = inside(lo, hi, grid_.mapLo(i), grid_.mapHi(i));
      if (!used) continue;
      held_.emplace(lo, traceSegment(lo, hi));
      ++stats_.segmentsTraced;
    }
    stats_.segmentSeconds += timer.seconds();
  }

  // Free what no frame after `frame` needs.
  void releaseBefore(int frame) {
    for (auto it = held_.begin(); it != held_.end();)
      it = it->second.hi <= grid_.mapLo(frame) ? held_.erase(it) : std::next(it);
  }

  // Time-invariant photons (ao.sharedScale > 0): the block of frames
  // [jK, (j+1)K) that `frame` is in (K = ao.window as given, so a frame's
  // image does not depend on the range a run renders), its shared set
  // traced when first needed. Segments classified for another block are
  // freed: which of their photons are kept depends on the block's motion.
  void enterBlock(int frame) {
    const int block = frame / ao_.window;
    if (shared_.block == block) return;
    Timer timer;
    held_.clear();
    shared_ = SharedSet{};
    shared_.block = block;
    const int f0 = block * ao_.window, f1 = int(std::min<int64_t>(anim_.frames - 1, int64_t(f0) + ao_.window - 1));
    const int64_t end = int64_t(anim_.frames) * grid_.binsPerFrame;
    shared_.lo = std::max<int64_t>(0, grid_.mapLo(f0));
    shared_.hi = std::min(end, grid_.mapHi(f1));
    const float t0 = float(double(shared_.lo) * grid_.binWidth), t1 = float(double(shared_.hi) * grid_.binWidth);
    shared_.motion = photon::motionBoundsOver(scene_, scene_.shutter.normalized(t0), scene_.shutter.normalized(t1));
    // Seeded alike for every block (common random numbers: the same paths,
    // so still light does not change between blocks) unless
    // --independent-frames.
    const uint64_t key = ao_.independentFrames ? uint64_t(block) : 0;
    const double mapShare = double(grid_.shutterBins + 2 * grid_.padBins) / double(grid_.shutterBins);
    for (MapKind kind : kAllMapKinds) {
      if (perShutter_[kind] == 0) continue;
      double rate = pilotRate(shared_.lo, shared_.hi, kind, hashCombine(opt_.seed, 0x5ea7ull, key));
      blockRate_[kind] = rate;
      if (!(rate > 0)) continue;
      // Paths: sharedScale times a frame's time map's, all kinds of photon
      // counted (the pilot's rate), of which the invariant ones are kept.
      photon::TraceSettings ts = traceSettingsFor(
          opt_, kind, size_t(std::max(1.0, std::round(double(perShutter_[kind]) * mapShare * ao_.sharedScale))),
          hashCombine(opt_.seed, 0x5a4edull, key));
      if (continuing()) {
        // Before tracing: every path of the block may meet motion and keep a
        // state (the rolling ball's caustic paths all do), as many paths as
        // the pilot's rate says, on top of the states already kept.
        const uint64_t paths = uint64_t(std::ceil(double(ts.storedWanted) / rate));
        checkKeptStatesMemory(paths, sizeof(photon::PathState),
                              uint64_t(shared_.keptStates()) * sizeof(photon::PathState), availableMemoryBytes(),
                              ao_.window);
      }
      ts.timeOpen = t0;
      ts.timeClose = t1;
      ts.invariant = photon::InvariantPhotons::Only;
      ts.motion = &shared_.motion;
      ts.keepMoving = continuing();
      photon::SegmentStore grid;
      grid.storeT0 = t0;
      grid.storeT1 = t1;
      grid.storedPerPath = rate;
      photon::TraceResult r = photon::traceSegmentPhotons(scene_, ts, grid, framed_);
      countTrace(kind, r);
      stats_.sharedPhotons += r.store.size();
      shared_.stores[kind] = std::move(r.store);
      shared_.kept[kind] = std::move(r.kept);
    }
    stats_.peakKeptStates = std::max(stats_.peakKeptStates, shared_.keptStates());
    ++stats_.sharedSets;
    stats_.sharedSeconds += timer.seconds();
  }
  const SharedSet* shared() const { return shared_.block >= 0 ? &shared_ : nullptr; }

  std::vector<const Segment*> segments() const {
    std::vector<const Segment*> segs;
    for (const auto& [lo, s] : held_) segs.push_back(&s);
    return segs;
  }
  size_t heldPhotons() const {
    size_t n = shared_.size();
    for (const auto& [lo, s] : held_) n += s.size();
    return n;
  }
  uint64_t emitted() const { return emitted_; }

 private:
  // Frames continue the block's paths that meet motion (section 8) rather
  // than trace theirs from the light: not in media (the walk of
  // photon/tracer_media.h keeps no states).
  bool continuing() const { return ao_.continuePaths && ao_.sharedScale > 0 && !scene_.hasMedia(); }
  // What every trace of a map adds to the totals (shared sets and segments).
  void countTrace(MapKind kind, const photon::TraceResult& r) {
    addWarning(stats_, r.warning);
    emitted_ += r.emitted;
    stats_.maps[kind].stored += r.store.size();
    stats_.maps[kind].emitted += r.emitted;
  }
  // Pilot: stored photons per path, once per frame period and kind, over
  // that frame's time map (the caustic map aims at where the specular
  // objects are then). Segments of the period size their emission by it,
  // so a frame's photons do not depend on the range or window of the run.
  double rateFor(int64_t period, MapKind kind) {
    auto key = std::pair{period, int(kind)};
    auto it = rates_.find(key);
    if (it != rates_.end()) return it->second;
    const int64_t timelineEnd = int64_t(anim_.frames) * grid_.binsPerFrame;
    int frame = int(std::clamp<int64_t>(period, 0, anim_.frames - 1));
    return rates_[key] = pilotRate(std::max<int64_t>(0, grid_.mapLo(frame)), std::min(timelineEnd, grid_.mapHi(frame)),
                                   kind, hashCombine(opt_.seed, 0x9170ull, uint64_t(period)));
  }

  // Stored photons per path of every kind's photons (InvariantPhotons::All)
  // over bins [lo, hi).
  double pilotRate(int64_t lo, int64_t hi, MapKind kind, uint64_t seed) {
    photon::TraceSettings ts = traceSettingsFor(opt_, kind, 1, seed);
    // Continuing (section 8): the block's pilot is most of what is left of
    // the frames' photon cost besides the shared set (16 batches per kind
    // against a global set of 3 in still-room); 4 batches measure the rate
    // to a few percent, which only sizes the counts (energies use the
    // emitted paths).
    if (continuing()) ts.pilotBatches = 4;
    ts.timeOpen = float(double(lo) * grid_.binWidth);
    ts.timeClose = float(double(hi) * grid_.binWidth);
    photon::TraceResult r = photon::tracePhotons(scene_, ts, Progress{});
    addWarning(stats_, r.warning);
    return r.storedPerPath;
  }

  Segment traceSegment(int64_t lo, int64_t hi) {
    Segment seg;
    seg.lo = lo;
    seg.hi = hi;
    // Seeded by the segment's place in its frame period, not by the
    // frame: corresponding paths of every frame use the same random
    // numbers, so still light on still geometry does not flicker
    // (--independent-frames: by the segment's absolute place instead).
    int64_t phase = lo % grid_.binsPerFrame;
    uint64_t key = ao_.independentFrames ? uint64_t(lo) | (uint64_t(1) << 62) : uint64_t(phase);
    const int64_t period = std::clamp<int64_t>((lo + grid_.padBins) / grid_.binsPerFrame, 0, anim_.frames - 1);
    // Outside every frame's shutter (cut points include every shutter end).
    const int64_t at = lo - (lo / grid_.binsPerFrame) * grid_.binsPerFrame;
    const bool pad = at >= grid_.shutterBins;
    for (MapKind kind : kAllMapKinds) {
      if (perShutter_[kind] == 0) continue;
      // Sharing: the block's pilot sizes its segments too (a pilot per
      // frame period traced more paths than a frame's global map).
      double rate = shared_.block >= 0 ? blockRate_[kind] : rateFor(period, kind);
      if (!(rate > 0)) continue;
      double share = double(hi - lo) / (double(grid_.binsPerFrame) * anim_.shutterAngle / 360.0);
      // Sharing: only the photons whose path meets the block's motion are
      // kept (the shared set has the others), from movingScale x the paths.
      if (shared_.block >= 0) share *= ao_.movingScale;
      photon::TraceSettings ts =
          traceSettingsFor(opt_, kind, size_t(std::max(1.0, std::round(double(perShutter_[kind]) * share))),
                           hashCombine(opt_.seed, key, uint64_t(hi - lo)));
      ts.timeOpen = float(double(lo) * grid_.binWidth);
      ts.timeClose = float(double(hi) * grid_.binWidth);
      if (shared_.block >= 0) {
        ts.invariant = photon::InvariantPhotons::None;
        ts.motion = &shared_.motion;
      }
      photon::TraceResult r;
      if (shared_.block >= 0 && continuing()) {
        r = continueSegment(lo, kind, ts, rate, period, key);
      } else {
        photon::SegmentStore grid;  // the timeline's bins, and the period's measured rate
        grid.storeT0 = ts.timeOpen;
        grid.storeT1 = float(double(lo + photon::kTimeBins) * grid_.binWidth);
        grid.storedPerPath = rate;
        r = photon::traceSegmentPhotons(scene_, ts, grid, framed_);
      }
      countTrace(kind, r);
      stats_.segmentPaths += r.emitted;
      stats_.segmentPhotons += r.store.size();
      if (pad) {
        stats_.padPaths += r.emitted;
        stats_.padPhotons += r.store.size();
      }
      seg.stores[kind] = std::move(r.store);
    }
    return seg;
  }

  // A segment's photons of the paths that meet motion, continued from the
  // block's kept states (section 8): as many virtual paths as the full
  // trace would emit (the same paths per second; a path that did not meet
  // motion stands for its invariant light, which the shared set holds), the
  // segment's virtual paths taking the block's paths at the segment's place
  // in its frame's map, so a frame's segments take disjoint block paths
  // when it has no more than the block pass (movingScale <= sharedScale),
  // and every frame takes the same ones at the same phase (common random
  // numbers; --independent-frames: fresh numbers per segment).
  photon::TraceResult continueSegment(int64_t lo, MapKind kind, const photon::TraceSettings& ts,
                                      double rate, int64_t period, uint64_t key) {
    const photon::KeptPaths& kept = shared_.kept[kind];
    const double wanted = double(ts.storedWanted);
    const double paths = std::min(wanted / rate, photon::kMaxPathsPerPhoton * wanted);
    photon::Continuation c;
    c.storeT0 = ts.timeOpen;
    c.storeT1 = float(double(lo + photon::kTimeBins) * grid_.binWidth);
    c.virtualPaths = uint64_t(std::max(1.0, std::ceil(paths)));
    const int64_t mapBins = grid_.shutterBins + 2 * grid_.padBins;
    const int64_t at = std::clamp<int64_t>(lo - grid_.mapLo(int(period)), 0, mapBins);
    c.firstVirtual = uint64_t(double(kept.emitted) * double(at) / double(mapBins));
    c.streamKey = ao_.independentFrames ? key : 0;
    photon::TraceResult r = photon::continuePaths(scene_, ts, kept, c, framed_);
    stats_.continuedPaths += r.continued;
    return r;
  }

  const Scene& scene_;
  const scene::AnimationDesc& anim_;
  const RenderOptions& opt_;
  const AnimationOptions& ao_;
  const TimeGrid& grid_;
  const PerMap<size_t> perShutter_;  // photons wanted per frame's shutter time, by kind
  const Progress& framed_;
  AnimationStats& stats_;
  const std::vector<int64_t> cuts_;
  std::map<std::pair<int64_t, int>, double> rates_;
  std::map<int64_t, Segment> held_;  // by lo
  SharedSet shared_;                 // the current block's (block -1: none)
  PerMap<double> blockRate_{};       // its pilot's stored photons per path, by kind
  uint64_t emitted_ = 0;
};

// One fixed-budget frame: its maps from the held segments, renderFrame, the
// sink. The maps are freed before the sink writes the frame.
void renderTimelineFrame(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                         const TimeGrid& grid, int frame, bool photons, bool spaceTime, const SegmentTimeline& timeline,
                         const Progress& framed, AnimationStats& stats, const FrameSink& sink) {
  FrameInput in;
  in.shutter = frameShutter(anim, frame);
  PerMap<std::unique_ptr<PhotonMap>> maps;
  size_t heldNow = timeline.heldPhotons();
  if (photons) {
    Timer mapTimer;
    std::vector<const Segment*> segs = timeline.segments();
    FrameMapSettings fs;
    fs.timelineEnd = int64_t(anim.frames) * grid.binsPerFrame;
    fs.spaceTime = spaceTime;
    fs.kappa = opt.kappa;
    fs.beam = resolvedBeamOptions(beamOptionsFor(opt), scene, opt.maxDtFraction, in.shutter.length());
    for (MapKind k : kAllMapKinds) {
      maps[k] = frameMap(segs, timeline.shared(), k, grid, frame, fs);
      in.maps[k] = maps[k].get();
      heldNow += maps[k]->store.size() + maps[k]->store3.size();
    }
    stats.photonSeconds += mapTimer.seconds();
    stats.mapSeconds += mapTimer.seconds();
  }
  stats.peakHeldPhotons = std::max(stats.peakHeldPhotons, heldNow);
  RenderStats st;
  Film film = renderFrame(scene, opt, in, framed, st);
  for (MapKind k : kAllMapKinds) {
    if (photons) st.maps[k].stored = maps[k]->ownPhotons;  // the frame's own shutter
    maps[k].reset();
  }
  sink(frame, std::move(film), st);
}

}  // namespace

// One level: the checks, the grid and the memory budget, then windows of
// frames: trace what the window needs, render its frames, free what no
// later frame needs.
AnimationStats renderAnimation(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                               const AnimationOptions& ao, const Progress& progress, const FrameSink& sink) {
  const RenderMethodTraits& method = renderMethodTraits(opt.method);
  if (!method.animation)
    throw Error("method '" + std::string(method.name) + "' cannot render an animation (use time, standard or pathtrace)");
  checkMediaSupport(scene, opt);
  TDPM_ASSERT(ao.first >= 0 && ao.last < anim.frames && ao.first <= ao.last && ao.window >= 1, "bad frame range");
  if (opt.progressive) return renderProgressiveFrames(scene, anim, opt, ao, progress, sink);
  AnimationStats stats;
  const double shutter = anim.shutterLength();
  const double reach = std::isfinite(opt.estimate.maxTimeDistance) ? opt.estimate.maxTimeDistance / shutter
                                                                     : double(opt.maxDtFraction);
  const TimeGrid grid = makeTimeGrid(anim, reach);
  const bool photons = method.photonMaps;
  const bool spaceTime = opt.spaceTime4D && method.timeDependentEstimate && scene.hasMotion;  // the 4D tree serves it alone
  const size_t total = size_t(ao.last - ao.first + 1);
  // A window wider than the frames rendered holds nothing more (issue 27
  // item 15: one frame with --window 100000 was budgeted for 100002 frames'
  // photons). Frames' photons do not depend on the window, so capping it
  // changes no image.
  const int window = int(std::min<int64_t>(ao.window, int64_t(total)));
  checkAnimationMemory(scene, opt, grid, window, ao.window, photons, photons ? ao.sharedScale : 0.0);

  std::string prefix;
  Progress framed;
  framed.report = [&](const std::string& stage, size_t done, size_t all) { progress(prefix + stage, done, all); };
  framed.position = progress.position;
  SegmentTimeline timeline(scene, anim, opt, ao, grid, photons ? photonsWanted(opt) : PerMap<size_t>{}, framed, stats);

  progress.at(WorkPosition{"frame", 0, total, 0, 0});
  const bool share = photons && ao.sharedScale > 0;
  for (int w0 = ao.first; w0 <= ao.last;) {
    // Sharing: windows are the blocks of ao.window frames from frame 0
    // (clipped to the range), each with its shared set.
    const int w1 = share ? std::min(ao.last, (w0 / ao.window + 1) * ao.window - 1) : std::min(ao.last, w0 + window - 1);
    Timer traceTimer;
    if (share) timeline.enterBlock(w0);
    if (photons) timeline.traceWindow(w0, w1);
    stats.photonSeconds += traceTimer.seconds();
    for (int i = w0; i <= w1; ++i) {
      prefix = "frame " + std::to_string(i) + " (" + std::to_string(i - ao.first + 1) + "/" + std::to_string(total) + "): ";
      renderTimelineFrame(scene, anim, opt, grid, i, photons, spaceTime, timeline, framed, stats, sink);
      progress.at(WorkPosition{"frame", size_t(i - ao.first + 1), total, 0, timeline.emitted()});
    }
    timeline.releaseBefore(w1 + 1);
    w0 = w1 + 1;
  }
  return stats;
}

}  // namespace tdpm
