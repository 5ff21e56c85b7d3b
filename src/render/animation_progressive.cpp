// render/animation_progressive.cpp — an animation's frames rendered in
// progressive passes (docs/animation.md section 6). Without sharing each
// frame is a progressive render of its own; with --shared-photons (scenes
// without media) the frames of a block of --window frames are rendered
// pass-interleaved and pass j of every frame of the block uses one set of
// time-invariant photons traced once for the block's pass j, plus the
// frame's own photons of the paths that meet motion (continued from that
// set's kept path states, or traced from the light).
#include "render/animation_progressive.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "core/memory.h"
#include "core/rng.h"
#include "core/signals.h"
#include "core/timer.h"
#include "photon/tracer.h"
#include "render/memory_budget.h"
#include "render/photon_map.h"
#include "render/progressive.h"
#include "render/progressive_check.h"

namespace tdpm {

namespace {

// Continue the paths that meet motion from the block pass's states
// (section 8), as the fixed-budget frames do.
bool continuing(const AnimationOptions& ao) { return ao.continuePaths; }

// Block of `frame`: frames [bK, min(bK + K, N) - 1] (K = --window as given,
// counted from frame 0, so a frame's block does not depend on the range).
void blockOf(const scene::AnimationDesc& anim, const AnimationOptions& ao, int frame, int& f0, int& f1) {
  f0 = (frame / ao.window) * ao.window;
  f1 = int(std::min<int64_t>(anim.frames - 1, int64_t(f0) + ao.window - 1));
}

std::string exact(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

// The time-invariant photons of one block, a pass at a time, and each
// frame's pass maps from them (docs/animation.md "Progressive frames
// sharing time-invariant photons"). Block time W = [open(f0), close(f1)].
class SharedPasses {
 public:
  SharedPasses(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
               const AnimationOptions& ao, int frame, AnimationStats& stats)
      : scene_(scene), opt_(opt), ao_(ao), stats_(stats), perShutter_(photonsWanted(opt)) {
    Timer timer;
    int f0, f1;
    blockOf(anim, ao, frame, f0, f1);
    t0_ = frameShutter(anim, f0).open;
    t1_ = frameShutter(anim, f1).close;
    motion_ = photon::motionBoundsOver(scene, scene.shutter.normalized(t0_), scene.shutter.normalized(t1_));
    // Seeded alike for every block (common random numbers, as the
    // fixed-budget blocks) unless --independent-frames.
    key_ = ao.independentFrames ? uint64_t(f0 / ao.window) + 1 : 0;
    for (MapKind kind : kAllMapKinds) {
      if (!used(kind)) continue;
      // Stored photons per path of every photon over W: sizes the shared
      // set and the frames' own paths, the same in every pass and run.
      photon::TraceSettings ts = traceSettingsFor(opt, kind, 1, hashCombine(opt.seed, 0x5ea7ull, key_));
      if (continuing(ao)) ts.pilotBatches = 4;
      ts.timeOpen = t0_;
      ts.timeClose = t1_;
      photon::TraceResult r = photon::tracePhotons(scene, ts, Progress{});
      if (!r.warning.empty()) warnings_.push_back(r.warning);
      rate_[kind] = r.storedPerPath;
    }
    seconds(timer);
  }

  // Pass `pass`'s maps for the frame with options `fo` (its shutter), the
  // block's set of that pass traced first if it is not the one held.
  PhotonMaps frameMaps(int frame, const RenderOptions& fo, int pass, const Progress& progress) {
    if (pass_ != pass) tracePass(pass, progress);
    PhotonMaps maps;
    for (MapKind kind : kAllMapKinds) {
      maps.maps[kind] = std::make_unique<PhotonMap>();
      if (!used(kind) || !(rate_[kind] > 0)) continue;
      PhotonMap& m = *maps.maps[kind];
      photon::TraceResult own = framePhotons(frame, fo, kind, pass, progress);
      m.emitted = own.emitted;
      m.traceSeconds = own.seconds;
      m.warning = own.warning;
      Timer build;
      // The shared photons join the frame's, each at its place q of 256 in
      // W spread over the shutter (uniform, as light that does not change)
      // with its energy per second of W times the shutter length.
      const photon::PhotonStore& sh = shared_[kind];
      m.store = std::move(own.store);
      m.store.reserve(m.store.size() + sh.size());
      const float toShutter = float((double(fo.frameClose) - double(fo.frameOpen)) / (double(t1_) - double(t0_)));
      for (size_t p = 0; p < sh.size(); ++p)
        m.store.addEncoded(sh.xs()[p], sh.ys()[p], sh.zs()[p],
                           photon::encodeRgbe(photon::decodeRgbe(sh.energies()[p]) * toShutter), sh.directions()[p],
                           sh.flags()[p], sh.timeBin(p));
      m.tree = photon::KdTree::build(m.store, {});
      m.buildSeconds = build.seconds();
    }
    return maps;
  }

  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  bool used(MapKind kind) const { return kind != MapKind::Volume && perShutter_[kind] > 0; }
  void seconds(const Timer& t) {
    stats_.sharedSeconds += t.seconds();
    stats_.photonSeconds += t.seconds();
  }

  // The block's pass `pass`: c x a frame's photons wanted (c =
  // --shared-photons) from paths over W, the invariant ones kept, with the
  // states of the others when continuing. Its own seed per pass: passes
  // are independent, as a still render's passes.
  void tracePass(int pass, const Progress& progress) {
    Timer timer;
    pass_ = pass;
    size_t kept = 0;
    for (MapKind kind : kAllMapKinds) {
      shared_[kind] = photon::PhotonStore();
      kept_[kind] = photon::KeptPaths{};
      if (!used(kind) || !(rate_[kind] > 0)) continue;
      photon::TraceSettings ts =
          traceSettingsFor(opt_, kind, size_t(std::max(1.0, std::round(double(perShutter_[kind]) * ao_.sharedScale))),
                           hashCombine(opt_.seed, hashCombine(0x5a4edull, key_), uint64_t(pass)));
      if (continuing(ao_))
        checkKeptStatesMemory(uint64_t(std::ceil(double(ts.storedWanted) / rate_[kind])), sizeof(photon::PathState),
                              uint64_t(kept) * sizeof(photon::PathState), availableMemoryBytes(), ao_.window);
      ts.timeOpen = t0_;
      ts.timeClose = t1_;
      ts.invariant = photon::InvariantPhotons::Only;
      ts.motion = &motion_;
      ts.keepMoving = continuing(ao_);
      photon::SegmentStore grid;
      grid.storeT0 = t0_;
      grid.storeT1 = t1_;
      grid.storedPerPath = rate_[kind];
      photon::TraceResult r = photon::traceSegmentPhotons(scene_, ts, grid, progress);
      stats_.sharedPhotons += r.store.size();
      stats_.maps[kind].emitted += r.emitted;
      shared_[kind] = std::move(r.store);
      kept_[kind] = std::move(r.kept);
      kept += kept_[kind].states.size();
    }
    stats_.peakKeptStates = std::max(stats_.peakKeptStates, kept);
    ++stats_.sharedSets;
    seconds(timer);
  }

  // The frame's own photons of pass `pass`: those of paths that meet the
  // block's motion, m x a frame's (m = --moving-photons), over its shutter,
  // from as many paths as a full trace would emit (whole batches: the
  // state's paths per pass), with the frame's energy per shutter second.
  photon::TraceResult framePhotons(int frame, const RenderOptions& fo, MapKind kind, int pass,
                                   const Progress& progress) {
    const double rate = rate_[kind];
    const double wanted = std::max(1.0, std::round(double(perShutter_[kind]) * ao_.movingScale));
    // Common random numbers: every frame of a block draws alike in a pass
    // (the frame enters only by its shutter), unless --independent-frames.
    const uint64_t key = ao_.independentFrames ? uint64_t(frame) + 1 : 0;
    photon::TraceSettings ts =
        traceSettingsFor(opt_, kind, size_t(wanted), hashCombine(opt_.seed, hashCombine(0xf7a3eull, key), uint64_t(pass)));
    ts.timeOpen = fo.frameOpen;
    ts.timeClose = fo.frameClose;
    if (continuing(ao_)) {
      photon::Continuation c;
      c.storeT0 = fo.frameOpen;
      c.storeT1 = fo.frameClose;
      // At most kMaxPathsPerPhoton per photon of the frame's count, as the
      // tracer caps a pass (and the resume check bounds pathsPerPass).
      const double paths = std::min(wanted / rate, photon::kMaxPathsPerPhoton * double(perShutter_[kind]));
      const double batches = std::max(1.0, std::ceil(paths / double(photon::kPathsPerBatch)));
      c.virtualPaths = uint64_t(batches) * photon::kPathsPerBatch;
      c.firstVirtual = 0;
      c.streamKey = ao_.independentFrames ? hashCombine(key, uint64_t(pass)) | 1u : 0;
      photon::TraceResult r = photon::continuePaths(scene_, ts, kept_[kind], c, progress);
      stats_.continuedPaths += r.continued;
      return r;
    }
    ts.invariant = photon::InvariantPhotons::None;
    ts.motion = &motion_;
    photon::SegmentStore grid;
    grid.storeT0 = fo.frameOpen;
    grid.storeT1 = fo.frameClose;
    grid.storedPerPath = rate;
    return photon::traceSegmentPhotons(scene_, ts, grid, progress);
  }

  const Scene& scene_;
  const RenderOptions& opt_;
  const AnimationOptions& ao_;
  AnimationStats& stats_;
  const PerMap<size_t> perShutter_;
  float t0_ = 0, t1_ = 0;
  photon::MotionBounds motion_;
  uint64_t key_ = 0;
  PerMap<double> rate_{};
  int pass_ = -1;  // the pass whose set is held
  PerMap<photon::PhotonStore> shared_;
  PerMap<photon::KeptPaths> kept_;
  std::vector<std::string> warnings_;
};

void addWarnings(AnimationStats& stats, const std::vector<std::string>& ws) {
  for (const std::string& w : ws)
    if (std::find(stats.warnings.begin(), stats.warnings.end(), w) == stats.warnings.end()) stats.warnings.push_back(w);
}

// A frame's figures into the sequence's, its state to the caller, the film to the sink.
void finishFrame(int frame, Film&& film, ProgressiveState&& state, int resumedAt, const RenderStats& st,
                 const AnimationOptions& ao, AnimationStats& stats, const FrameSink& sink) {
  addWarnings(stats, st.warnings);
  stats.photonSeconds += st.photonSeconds;
  for (MapKind k : kAllMapKinds) {
    stats.maps[k].stored += st.maps[k].stored;
    stats.maps[k].emitted += st.maps[k].emitted;
  }
  stats.passesDone += uint64_t(state.passesDone - resumedAt);  // this run's
  if (ao.keepState) ao.keepState(frame, std::move(state));
  sink(frame, std::move(film), st);
}

uint64_t emittedOf(const RenderStats& st) {
  uint64_t e = 0;
  for (MapKind k : kAllMapKinds) e += st.maps[k].emitted;
  return e;
}

Progress framedProgress(const Progress& progress, int i, int first, size_t total) {
  const std::string prefix =
      "frame " + std::to_string(i) + " (" + std::to_string(i - first + 1) + "/" + std::to_string(total) + "): ";
  Progress framed;  // stages prefixed by the frame; the pass positions stay the frame loop's
  framed.report = [&progress, prefix](const std::string& stage, size_t done, size_t all) {
    progress(prefix + stage, done, all);
  };
  return framed;
}

// One frame in the block's loop.
struct BlockFrame {
  int index = 0;
  RenderOptions opt;
  ProgressiveState state;
  ProgressiveStart start;
  RenderStats st;
  Progress framed;
  int resumedAt = 0;
  double seconds = 0;
  bool wants() const {
    return (opt.passes <= 0 || state.passesDone < opt.passes) && state.passesDone < maxProgressivePasses();
  }
};

// The frames [b0, b1] of one block (sharing): pass-interleaved, each round
// the frames at the fewest passes (a resumed block may have frames at
// different counts) run their next pass on the block's set of that pass.
// --passes is per frame; --time-limit S gives the block S x its frames
// (each round is every behind frame's pass, so the frames keep step).
void renderSharedBlock(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                       const AnimationOptions& ao, int b0, int b1, const Progress& progress, size_t& done,
                       uint64_t& emitted, AnimationStats& stats, const FrameSink& sink) {
  const size_t total = size_t(ao.last - ao.first + 1);
  std::vector<BlockFrame> frames;
  for (int i = b0; i <= b1; ++i) {
    BlockFrame f;
    f.index = i;
    f.opt = progressiveFrameOptions(scene, anim, opt, ao, i);
    f.state = ao.startState ? ao.startState(i, f.opt) : ProgressiveState{};
    if (opt.passes > 0 && f.state.passesDone >= opt.passes) {  // finished in an earlier run: its file stays
      ++stats.framesSkipped;
      progress.at(WorkPosition{"frame", ++done, total, 0, emitted});
      continue;
    }
    frames.push_back(std::move(f));
  }
  if (frames.empty()) return;
  // The frames' states (7 float layers a pixel each: render/progressive_state.h).
  const uint64_t pixels = uint64_t(scene.camera.width()) * uint64_t(scene.camera.height());
  checkBlockStatesMemory(frames.size(), pixels * 7 * sizeof(float), availableMemoryBytes(), ao.window);
  SharedPasses shared(scene, anim, opt, ao, b0, stats);
  addWarnings(stats, shared.warnings());
  Timer timer;
  for (BlockFrame& f : frames) {
    f.framed = framedProgress(progress, f.index, ao.first, total);
    f.resumedAt = f.state.passesDone;
    f.start = startProgressive(scene, f.opt, f.state, f.framed, f.st);
  }
  const double limit = frames[0].start.limit * double(frames.size());
  for (;;) {
    int pass = -1;
    for (const BlockFrame& f : frames)
      if (f.wants() && (pass < 0 || f.state.passesDone < pass)) pass = f.state.passesDone;
    if (pass < 0) break;
    for (BlockFrame& f : frames) {
      if (!f.wants() || f.state.passesDone != pass) continue;
      Timer t;
      runProgressivePass(scene, f.opt, f.state, f.framed, f.st, f.start.counts,
                         [&](int p, const Progress& pr) { return shared.frameMaps(f.index, f.opt, p, pr); });
      f.seconds += t.seconds();
    }
    if (limit > 0 && timer.seconds() >= limit) break;
    if (signals::stopRequested()) break;
  }
  for (BlockFrame& f : frames) {
    Film film = finishProgressive(scene, f.state, f.st, f.seconds);
    emitted += emittedOf(f.st);
    finishFrame(f.index, std::move(film), std::move(f.state), f.resumedAt, f.st, ao, stats, sink);
    progress.at(WorkPosition{"frame", ++done, total, 0, emitted});
  }
}

}  // namespace

bool progressiveFramesShare(const Scene& scene, const RenderOptions& opt, const AnimationOptions& ao) {
  return opt.progressive && ao.sharedScale > 0 && !scene.hasMedia();
}

RenderOptions progressiveFrameOptions(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                                      const AnimationOptions& ao, int frame) {
  RenderOptions fo = opt;
  const Shutter sh = frameShutter(anim, frame);
  fo.frameOpen = sh.open;
  fo.frameClose = sh.close;
  if (progressiveFramesShare(scene, opt, ao)) {
    int f0, f1;
    blockOf(anim, ao, frame, f0, f1);
    fo.frameSharing = "frames " + std::to_string(f0) + "-" + std::to_string(f1) + " (window " +
                      std::to_string(ao.window) + "), shared " + exact(ao.sharedScale) + ", moving " +
                      exact(ao.movingScale) + (continuing(ao) ? ", continued" : ", traced") +
                      (ao.independentFrames ? ", independent" : "");
  }
  return fo;
}

AnimationStats renderProgressiveFrames(const Scene& scene, const scene::AnimationDesc& anim, const RenderOptions& opt,
                                       const AnimationOptions& ao, const Progress& progress, const FrameSink& sink) {
  AnimationStats stats;
  const size_t total = size_t(ao.last - ao.first + 1);
  progress.at(WorkPosition{"frame", 0, total, 0, 0});
  uint64_t emitted = 0;
  size_t done = 0;
  if (progressiveFramesShare(scene, opt, ao)) {
    for (int b0 = ao.first; b0 <= ao.last;) {
      const int b1 = std::min(ao.last, (b0 / ao.window + 1) * ao.window - 1);
      renderSharedBlock(scene, anim, opt, ao, b0, b1, progress, done, emitted, stats, sink);
      b0 = b1 + 1;
    }
    return stats;
  }
  // Without sharing: each frame a progressive render of its own.
  for (int i = ao.first; i <= ao.last; ++i) {
    const Progress framed = framedProgress(progress, i, ao.first, total);
    RenderOptions frameOpt = progressiveFrameOptions(scene, anim, opt, ao, i);
    ProgressiveState state = ao.startState ? ao.startState(i, frameOpt) : ProgressiveState{};
    if (opt.passes > 0 && state.passesDone >= opt.passes) {  // finished in an earlier run: its file stays
      ++stats.framesSkipped;
      progress.at(WorkPosition{"frame", ++done, total, 0, emitted});
      continue;
    }
    const int resumedAt = state.passesDone;
    RenderStats st;
    Film film = renderProgressive(scene, frameOpt, state, framed, st);
    emitted += emittedOf(st);
    finishFrame(i, std::move(film), std::move(state), resumedAt, st, ao, stats, sink);
    progress.at(WorkPosition{"frame", ++done, total, 0, emitted});
  }
  return stats;
}

}  // namespace tdpm
