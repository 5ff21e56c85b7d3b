// core/signals.h — what SIGINT, SIGTERM, SIGHUP and SIGUSR1 do to a tdpm run.
// Owns: the signal handlers, the registry of temporary files a signal must
// remove, the "stop requested" flag, and deferral around short critical
// sections (renaming a finished output pair into place), and the child
// process (ffmpeg) a signal must end with tdpm.
// Why here: every output goes through core/atomic_file, which registers its
// temporary; a progressive renderer will switch to StopMode and poll
// stopRequested(). Everything the handler touches is async-signal-safe
// (fixed slots of lock-free atomics and char arrays, unlink, write, raise).
#pragma once

namespace tdpm::signals {

enum class Mode {
  // The first SIGINT/SIGTERM/SIGHUP removes the registered temporaries, prints
  // "tdpm: interrupted by SIGINT (temporary files removed)" and ends the process
  // by the same signal (the shell reports 128+signo: 130 for Ctrl-C).
  Exit,
  // The first signal only sets stopRequested() (the caller finishes cleanly);
  // a second one acts as in Exit mode, at once.
  Stop,
};

// Installs the handlers for SIGINT, SIGTERM, SIGHUP (a closed terminal)
// and SIGUSR1 (idempotent). SIGUSR1 is the one mpirun forwards to every
// rank without killing them a second later, as it does after SIGTERM: the
// documented "stop and write" signal of a progressive job
// (docs/distributed.md). A signal the parent set to SIG_IGN (e.g. `nohup`,
// background jobs) stays ignored.
void install(Mode mode = Mode::Exit);
void setMode(Mode mode);
// Whether the first signal in Stop mode prints "tdpm: stopping ..." (on by
// default; off on the ranks of an mpirun job other than rank 0, so that
// a signal mpirun forwards to every rank is announced once).
void setStopNotice(bool on);

// The signal number that asked to stop, 0 if none.
int stopRequested();

// Registry of temporaries to unlink on a signal. add() copies `path`
// (at most kMaxPath-1 bytes; longer paths are not registered and false is
// returned) into a free slot; remove() frees it. Thread-safe. Returns false
// too when all kSlots slots are taken.
constexpr int kSlots = 32;
constexpr int kMaxPath = 4096;
bool addTemporary(const char* path);
void removeTemporary(const char* path);

// The signal postponed by a Deferral (0: none): work that would be thrown
// away when the deferral ends (starting ffmpeg, renaming its video) can
// skip itself.
int pendingSignal();

// While an object lives, `pid` is a child process that must not outlive
// tdpm: a signal that ends tdpm (or is postponed by a Deferral to do so)
// first kills it (SIGKILL; the caller's waitpid then returns), so that
// ffmpeg does not go on writing into a folder tdpm removes (issue 27 item
// 13). A signal already pending when it is made kills the child at once.
// One child at a time.
class ChildGuard {
 public:
  explicit ChildGuard(int pid);
  ~ChildGuard();
  ChildGuard(const ChildGuard&) = delete;
  ChildGuard& operator=(const ChildGuard&) = delete;
};

// While an object lives (any thread), a signal's action is postponed until
// the last one ends: renames of an output pair are never cut in half.
class Deferral {
 public:
  Deferral();
  ~Deferral();
  Deferral(const Deferral&) = delete;
  Deferral& operator=(const Deferral&) = delete;
};

}  // namespace tdpm::signals
