// core/signals.cpp — SIGINT/SIGTERM/SIGHUP/SIGUSR1 handlers, the temporary-file registry
// and deferral. Only async-signal-safe calls inside the handler.
#include "core/signals.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <initializer_list>

namespace tdpm::signals {
namespace {

// A slot: 0 free, 1 being filled or emptied, 2 holds a path.
struct Slot {
  std::atomic<int> state{0};
  char path[kMaxPath];
};
Slot gSlots[kSlots];

std::atomic<int> gMode{int(Mode::Exit)};
std::atomic<int> gStop{0};         // signo of the first signal
std::atomic<int> gDeferrals{0};    // live Deferral objects
std::atomic<int> gPending{0};      // signo postponed by a Deferral
std::atomic<bool> gInstalled{false};
std::atomic<bool> gSayStopping{true};  // the stop mode's "stopping" line
std::atomic<int> gChild{0};        // ChildGuard's process, 0 if none

static_assert(std::atomic<int>::is_always_lock_free, "signal handler needs lock-free atomics");

void writeStderr(const char* s) {
  ssize_t r = ::write(STDERR_FILENO, s, std::strlen(s));
  (void)r;
}

void unlinkTemporaries() {
  for (Slot& s : gSlots)
    if (s.state.load() == 2) ::unlink(s.path);
}

// Removes the temporaries, says so, and dies by `signo` with the default
// action, so the parent sees a death by that signal (shell: 128+signo).
[[noreturn]] void terminate(int signo) {
  unlinkTemporaries();
  // Starts with a newline: a progress bar may hold the current line.
  writeStderr(signo == SIGINT     ? "\ntdpm: interrupted by SIGINT (temporary files removed)\n"
              : signo == SIGHUP  ? "\ntdpm: hung up (SIGHUP; temporary files removed)\n"
              : signo == SIGUSR1 ? "\ntdpm: stopped by SIGUSR1 (temporary files removed)\n"
                                 : "\ntdpm: terminated by SIGTERM (temporary files removed)\n");
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = SIG_DFL;
  sigemptyset(&sa.sa_mask);
  ::sigaction(signo, &sa, nullptr);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, signo);
  ::pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(signo);
  ::_exit(128 + signo);  // not reached
}

void handler(int signo) {
  int first = 0;
  bool isFirst = gStop.compare_exchange_strong(first, signo);
  if (isFirst && gMode.load() == int(Mode::Stop)) {
    if (gSayStopping.load()) writeStderr("\ntdpm: stopping (send the signal again to abort at once)\n");
    return;
  }
  // This signal ends tdpm (now or when the deferral ends): the child first.
  if (int child = gChild.load(); child > 0) ::kill(child, SIGKILL);
  if (gDeferrals.load() > 0) {
    gPending.store(signo);
    return;
  }
  terminate(signo);
}

}  // namespace

void install(Mode mode) {
  gMode.store(int(mode));
  bool expected = false;
  if (!gInstalled.compare_exchange_strong(expected, true)) return;
  for (int signo : {SIGINT, SIGTERM, SIGHUP, SIGUSR1}) {
    struct sigaction old;
    if (::sigaction(signo, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);  // one handler at a time
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaddset(&sa.sa_mask, SIGHUP);
    sigaddset(&sa.sa_mask, SIGUSR1);
    sa.sa_flags = SA_RESTART;
    ::sigaction(signo, &sa, nullptr);
  }
}

void setMode(Mode mode) { gMode.store(int(mode)); }

void setStopNotice(bool on) { gSayStopping.store(on); }

int stopRequested() { return gStop.load(); }

bool addTemporary(const char* path) {
  size_t n = std::strlen(path);
  if (n >= size_t(kMaxPath)) return false;
  for (Slot& s : gSlots) {
    int expected = 0;
    if (!s.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(s.path, path, n + 1);
    s.state.store(2);
    return true;
  }
  return false;
}

void removeTemporary(const char* path) {
  for (Slot& s : gSlots) {
    int expected = 2;
    if (s.state.load() != 2 || std::strcmp(s.path, path) != 0) continue;
    if (s.state.compare_exchange_strong(expected, 1)) {
      s.path[0] = '\0';
      s.state.store(0);
      return;
    }
  }
}

int pendingSignal() { return gPending.load(); }

ChildGuard::ChildGuard(int pid) {
  gChild.store(pid);
  // A signal that came before the store did not see the child.
  if (gPending.load() != 0) ::kill(pid, SIGKILL);
}

ChildGuard::~ChildGuard() { gChild.store(0); }

Deferral::Deferral() { gDeferrals.fetch_add(1); }

Deferral::~Deferral() {
  if (gDeferrals.fetch_sub(1) == 1) {
    int signo = gPending.exchange(0);
    if (signo != 0) terminate(signo);
  }
}

}  // namespace tdpm::signals
