// cli/animation_command.cpp — the frames of an animation to files, and the
// video preview by ffmpeg (run as a child process, never through a shell).
#include "cli/animation_command.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "cli/frame_pattern.h"
#include "cli/path_names.h"
#include "distributed/comm.h"
#include "photon/tracer.h"
#include "cli/progress_bar.h"
#include "cli/resume.h"
#include "cli/render_metadata.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/signals.h"
#include "core/temp_dir.h"
#include "core/memory.h"
#include "core/timer.h"
#include "image/png.h"
#include "render/animation.h"
#include "render/film_output.h"
#include "render/progressive_io.h"
#include "render/threads.h"
#include "scene/scene.h"

namespace tdpm::cli {

namespace fs = std::filesystem;

namespace {

// Creates `dir` and its parents; names the flag and the directory on failure.
void makeDirectories(const std::string& dir, const std::string& flag) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(flag + ": cannot create directory '" + dir + "' (" + ec.message() + ")");
  if (access(dir.c_str(), W_OK) != 0)
    throw Error(flag + ": cannot write to directory '" + dir + "' (" + std::strerror(errno) + ")");
}

// Runs ffmpeg (argv[0] is its full path) with stdout and stderr into `log`;
// returns its exit status (-1: did not run or was killed).
int runProcess(const std::vector<std::string>& argv, const std::string& log) {
  std::vector<char*> args;
  for (const std::string& s : argv) args.push_back(const_cast<char*>(s.c_str()));
  args.push_back(nullptr);
  if (signals::pendingSignal()) return -1;  // tdpm is ending: no ffmpeg to start
  const pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    // If tdpm is SIGKILLed (no handler runs), the kernel ends ffmpeg too
    // rather than leaving it orphaned; the getppid check covers a parent
    // that died between fork and prctl.
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);
    int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    int in = open("/dev/null", O_RDONLY);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    if (in >= 0) dup2(in, 0);
    execv(args[0], args.data());
    _exit(127);
  }
  signals::ChildGuard child(pid);  // a signal kills ffmpeg, and waitpid returns
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string readTail(const std::string& path, size_t max) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string s = ss.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s.size() > max ? "..." + s.substr(s.size() - max) : s;
}

// The PNG previews, in order, as a video: numbered links in a temporary
// directory beside the video, ffmpeg writes into it, and the result is
// renamed into place (a failure leaves any old video as it was).
void assembleVideo(const std::string& ffmpeg, const std::string& video, const std::vector<std::string>& previews,
                   double fps) {
  // SIGINT/SIGTERM/SIGHUP while the video is made: ffmpeg is killed at once
  // (signals::ChildGuard), the folder is removed by `cleanup` below, and
  // only then, when this deferral ends, does the signal end tdpm (it used
  // to leave the folder and a running ffmpeg; issue 27 item 13).
  signals::Deferral untilCleanedUp;
  // ".tdpm-video-<pid>-XXXXXX": a later run removes those of dead (SIGKILLed) runs.
  std::string tmp = makeWorkFolder(directoryOf(video), ".tdpm-video-", "--video");
  struct Cleanup {
    std::string dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{tmp};
  for (size_t i = 0; i < previews.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/%06zu.png", i);
    std::error_code ec;
    fs::create_symlink(fs::absolute(previews[i]), tmp + name, ec);
    if (ec) throw Error("--video: cannot link '" + previews[i] + "' (" + ec.message() + ")");
  }
  bool gif = endsWith(video, ".gif");
  std::string out = tmp + (gif ? "/video.gif" : "/video.mp4");
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.9g", fps);
  std::vector<std::string> argv{ffmpeg, "-nostdin", "-y", "-loglevel", "error", "-framerate", rate,
                                "-i", tmp + "/%06d.png"};
  if (!gif) {
    // H.264 in yuv420p (what players accept) needs even sizes.
    for (const char* a : {"-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-pix_fmt", "yuv420p"}) argv.push_back(a);
  }
  argv.push_back(out);
  std::string log = tmp + "/ffmpeg.log";
  int code = runProcess(argv, log);
  if (signals::pendingSignal()) throw Error("--video: interrupted");  // not shown: the signal ends tdpm first
  if (code != 0)
    throw Error("--video: ffmpeg failed (exit status " + std::to_string(code) + ") making '" + video +
                "': " + readTail(log, 600));
  if (std::rename(out.c_str(), video.c_str()) != 0)
    throw Error("--video: cannot rename the video into '" + video + "' (" + std::strerror(errno) + ")");
}

}  // namespace

std::string findOnPath(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::string p(path);
  size_t start = 0;
  while (start <= p.size()) {
    size_t end = p.find(':', start);
    if (end == std::string::npos) end = p.size();
    std::string dir = p.substr(start, end - start);
    if (dir.empty()) dir = ".";
    std::string full = dir + "/" + name;
    struct stat st;
    if (stat(full.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(full.c_str(), X_OK) == 0) return full;
    start = end + 1;
  }
  return "";
}

namespace {

// Where the frames go: the range, every frame's EXR and PNG, and ffmpeg for --video.
struct FrameOutputs {
  FrameRange range;
  std::string pattern, ffmpeg;
  std::vector<std::string> outputs, previews;
};

// Everything that can be wrong with the frames' outputs, before any file is
// made; then the output directories are created (only now). Throws tdpm::Error.
void prepareFrameOutputs(const RenderArgs& a, const scene::AnimationDesc& anim, const RenderOptions& opt,
                         FrameOutputs& f) {
  f.range = FrameRange{0, anim.frames - 1};
  if (a.frameRange) f.range = parseFrameRange(*a.frameRange, anim.frames);
  f.pattern = a.output.empty() ? stemOf(a.scene) + (f.range.count() > 1 ? "_####.exr" : ".exr") : a.output;
  checkFramePattern(f.pattern, f.range);
  if (!renderMethodTraits(opt.method).animation)
    throw Error("--method: '" + std::string(renderMethodName(opt.method)) +
                "' cannot render an animation (use time, standard or pathtrace)");
  if (a.video) {
    if (!endsWith(*a.video, ".mp4") && !endsWith(*a.video, ".gif"))
      throw Error("--video: '" + *a.video + "' must end in .mp4 or .gif");
    f.ffmpeg = findOnPath("ffmpeg");
    if (f.ffmpeg.empty())
      throw Error("--video: ffmpeg was not found on PATH; install it (Debian: apt-get install ffmpeg) or leave out "
                  "--video (the PNG previews are written either way)");
  }
  for (int i = f.range.first; i <= f.range.last; ++i) {
    f.outputs.push_back(formatFramePath(f.pattern, i));
    f.previews.push_back(image::previewPathFor(f.outputs.back()));
  }
  // Only now is anything created: the output directories.
  for (size_t i = 0; i < f.outputs.size(); ++i) {
    if (i == 0 || directoryOf(f.outputs[i]) != directoryOf(f.outputs[i - 1]))
      makeDirectories(directoryOf(f.outputs[i]), "--output");
    try {
      checkOutputPath(f.outputs[i]);
      checkOutputPath(f.previews[i]);
    } catch (const Error& e) {
      throw Error(std::string("--output: ") + e.what());
    }
    for (const std::string* o : {&f.outputs[i], &f.previews[i]})
      if (sameFile(*o, a.scene)) throw Error("--output: '" + *o + "' is the scene file '" + a.scene + "'");
  }
  if (a.video) {
    makeDirectories(directoryOf(*a.video), "--video");
    try {
      checkOutputPath(*a.video);
    } catch (const Error& e) {
      throw Error(std::string("--video: ") + e.what());
    }
  }
}

// --progressive: frame i starts from the state in --resume's frame i file
// when that file exists (checked as still resume checks it, against the
// frame's own options), else from a fresh state with the frame's
// fingerprint, which the frame's EXR then carries (docs/animation.md
// "Resuming progressive frames").
ProgressiveState frameStartState(const RenderArgs& a, const scene::SceneDescription& desc, int frame,
                                 const RenderOptions& frameOptions) {
  if (a.resume) {
    const std::string path = formatFramePath(*a.resume, frame);
    std::error_code ec;
    if (fs::exists(path, ec)) return loadResumeState(path, desc, frameOptions);
  }
  return initialProgressiveState(nullptr, desc, frameOptions);
}

// Every frame's --resume file is checked before any frame is rendered, so a
// wrong one costs no render and writes nothing.
void checkResumeFiles(const RenderArgs& a, const scene::SceneDescription& desc, const Scene& scene,
                      const scene::AnimationDesc& anim, const RenderOptions& opt, const AnimationOptions& ao) {
  if (!a.resume) return;
  for (int i = ao.first; i <= ao.last; ++i)
    (void)frameStartState(a, desc, i, progressiveFrameOptions(scene, anim, opt, ao, i));
}

// One written frame, for the summary.
struct FrameLine {
  int frame;
  double seconds;
  uint64_t samples;
  int minSpp, maxSpp;
};

// Rank 0's lines once every frame is written: one per frame, the summary, --stats.
void printAnimationSummary(const RenderArgs& a, const RenderOptions& opt, const FrameOutputs& f,
                           const std::vector<FrameLine>& lines, const AnimationStats& stats, const Scene& scene,
                           double allSeconds, uint64_t peakRss) {
  if (!a.quiet) {
    for (const FrameLine& l : lines)
      std::fprintf(stderr, "tdpm: frame %d: %.2f s, %d-%d samples per pixel -> %s\n", l.frame, l.seconds, l.minSpp,
                   l.maxSpp, f.outputs[size_t(l.frame - f.range.first)].c_str());
    double all = allSeconds;
    std::string storedText;  // "N caustic, M global"
    for (MapKind k : kAllMapKinds)
      if (mapKindReported(k, stats.maps[k]))
      storedText += (storedText.empty() ? "" : ", ") + std::to_string(stats.maps[k].stored) + " " + mapKindName(k);
    std::fprintf(stderr,
                 "tdpm: %s, %s: %d frames (%d-%d) at %dx%d, %.2f s in all, %.2f s per frame; photons: %s stored in "
                 "%llu %s, %.2f s%s%s\n",
                 a.scene.c_str(), renderMethodName(opt.method), f.range.count(), f.range.first, f.range.last,
                 scene.camera.width(), scene.camera.height(), all, all / double(f.range.count()),
                 storedText.c_str(),
                 static_cast<unsigned long long>(opt.progressive ? stats.passesDone : stats.segmentsTraced),
                 opt.progressive ? "passes" : "segments", stats.photonSeconds,
                 a.video ? " -> video " : "", a.video ? a.video->c_str() : "");
  }
  if (a.stats) {
    std::fprintf(stderr, "tdpm: stats:\n");
    std::fprintf(stderr, "  peak resident memory: %llu bytes\n", static_cast<unsigned long long>(peakRss));
    std::fprintf(stderr, "  peak photons held: %zu\n", stats.peakHeldPhotons);
    std::fprintf(stderr, "  photon pass: %.3f s\n", stats.photonSeconds);
    if (!opt.progressive)
      std::fprintf(stderr, "    of it: shared sets (with their pilots) %.3f s, frames' segments %.3f s, frame maps and trees %.3f s\n",
                   stats.sharedSeconds, stats.segmentSeconds, stats.mapSeconds);
    if (stats.segmentPaths > 0)
      std::fprintf(stderr, "  frames' own segments: %llu paths, %zu photons; of them the pads: %llu paths (%.1f%%), %zu photons (%.1f%%)\n",
                   static_cast<unsigned long long>(stats.segmentPaths), stats.segmentPhotons,
                   static_cast<unsigned long long>(stats.padPaths), 100.0 * double(stats.padPaths) / double(stats.segmentPaths),
                   stats.padPhotons, stats.segmentPhotons ? 100.0 * double(stats.padPhotons) / double(stats.segmentPhotons) : 0.0);
    if (stats.sharedSets > 0)
      std::fprintf(stderr, "  time-invariant photons: %zu stored in %llu shared sets\n", stats.sharedPhotons,
                   static_cast<unsigned long long>(stats.sharedSets));
    if (stats.continuedPaths > 0 || stats.peakKeptStates > 0)
      std::fprintf(stderr, "  continued paths: %llu of the segments' paths continued from kept states (at most %zu held, %zu bytes)\n",
                   static_cast<unsigned long long>(stats.continuedPaths), stats.peakKeptStates,
                   stats.peakKeptStates * sizeof(photon::PathState));
  }
}

// The flags' animation options and this rank's frames. Under mpirun the
// frames are split over the ranks in contiguous blocks (a frame's image
// depends only on its index, so any split writes what one process would),
// each rank writing its own frames; rank 0 prints and assembles the video
// once every rank has finished (docs/distributed.md). Progressive frames
// sharing a block's photons are split by whole blocks of --window frames,
// so that no two ranks trace one block's sets.
AnimationOptions rankAnimationOptions(const RenderArgs& a, const Scene& scene, const RenderOptions& opt,
                                      const FrameOutputs& f, dist::Comm& comm) {
  AnimationOptions ao;
  ao.window = a.window.value_or(ao.window);
  ao.independentFrames = a.independentFrames;
  ao.sharedScale = a.sharedPhotons.value_or(ao.sharedScale);
  ao.movingScale = a.movingPhotons.value_or(ao.movingScale);
  if (a.continuePaths || a.noContinuePaths) ao.continuePaths = a.continuePaths;
  const int unit = progressiveFramesShare(scene, opt, ao) ? ao.window : 1;
  const int firstFrame = f.range.first, lastFrame = f.range.first + int(f.range.count()) - 1;
  const int u0 = firstFrame / unit, u1 = lastFrame / unit;
  uint64_t lo = 0, hi = 0;
  dist::blockRange(uint64_t(u1 - u0 + 1), comm.rank(), comm.size(), lo, hi);
  ao.first = std::max(firstFrame, (u0 + int(lo)) * unit);
  ao.last = lo == hi ? ao.first - 1 : std::min(lastFrame, (u0 + int(hi)) * unit - 1);
  return ao;
}

}  // namespace

// One level: the outputs (every rank checks), this rank's block of frames
// rendered and written, rank 0's video and summary.
int runAnimation(const RenderArgs& a, const scene::SceneDescription& descIn, const RenderOptions& opt,
                 float exposure) {
  Timer total;
  const scene::AnimationDesc& anim = *descIn.animation;
  // Under mpirun every rank checks; an error is reported once by rank 0 and
  // every rank exits 1 (dist::raiseIfAnyFailed).
  dist::Comm& comm = dist::world();
  FrameOutputs f;
  std::string setupError;
  try {
    prepareFrameOutputs(a, anim, opt, f);
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    setupError = e.what();
  }
  dist::raiseIfAnyFailed(comm, setupError);

  ThreadLimit limit(a.threads);
  std::FILE* barStream = ProgressBar::stream(a.quiet, comm.distributed());  // none under mpirun
  ProgressBar bar(comm.root() && barStream, barStream ? barStream : stderr);
  auto scene = Scene::build(descIn);
  AnimationOptions ao = rankAnimationOptions(a, *scene, opt, f, comm);
  std::optional<ProgressiveState> kept;  // the frame's state, written with it
  if (opt.progressive) {
    ao.startState = [&](int i, const RenderOptions& fo) { return frameStartState(a, descIn, i, fo); };
    ao.keepState = [&](int, ProgressiveState&& st) { kept = std::move(st); };
  }
  std::vector<FrameLine> lines;
  uint64_t peakRss = 0;
  Timer frameTimer;
  AnimationStats stats;
  std::string frameError;
  try {
    if (opt.progressive && ao.first <= ao.last) {
      if (a.resume) checkFramePattern(*a.resume, f.range, "--resume");
      checkResumeFiles(a, descIn, *scene, anim, opt, ao);
    }
    if (ao.first <= ao.last)
      stats = renderAnimation(*scene, anim, opt, ao, bar.progress(), [&](int i, Film&& film, const RenderStats& st) {
        size_t k = size_t(i - f.range.first);
        image::ExrFile exr = filmToExr(std::move(film));
        const FrameTag tag{i, double(anim.frameOpen(i)), double(anim.frameClose(i))};
        exr.metadata = renderMetadata(a.scene, opt, st, &tag);
        if (kept) addProgressiveState(std::move(*kept), exr);
        kept.reset();
        writeRenderOutputs(f.outputs[k], f.previews[k], exr, exposure);
        // A progressive frame's own passes (frames sharing a block's photons
        // are written together after the block's last round: the time since
        // the last frame was written would give the block's to its first).
        lines.push_back({i, opt.progressive ? st.seconds : frameTimer.seconds(), st.cameraSamples, st.minSpp, st.maxSpp});
        frameTimer.reset();
        peakRss = std::max(peakRss, st.peakResidentBytes);
      });
  } catch (const Error& e) {
    if (!comm.distributed()) throw;
    frameError = e.what();
  }
  // Every rank's frames are written before the video is made; a failure on
  // any rank is reported once and every rank exits 1.
  dist::raiseIfAnyFailed(comm, frameError);
  if (!comm.root()) return 0;
  if (a.video) assembleVideo(f.ffmpeg, *a.video, f.previews, anim.fps);
  bar.finish();
  for (const std::string& w : stats.warnings) std::fprintf(stderr, "tdpm: warning: %s\n", w.c_str());
  peakRss = std::max(peakRss, peakResidentBytes());
  printAnimationSummary(a, opt, f, lines, stats, *scene, total.seconds(), peakRss);
  return 0;
}

}  // namespace tdpm::cli
