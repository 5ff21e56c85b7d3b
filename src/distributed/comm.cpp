// distributed/comm.cpp — the one-process Comm, the helpers built on any Comm, the
// launcher detection and the MPI session (distributed/mpi_comm.cpp does the MPI).
#include "distributed/comm.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#ifdef TDPM_MPI
#include "distributed/mpi_backend.h"
#endif

namespace tdpm::dist {

namespace {

class LocalCounter final : public SharedCounter {
 public:
  uint64_t fetchAdd(uint64_t n) override { return value_.fetch_add(n); }

 private:
  std::atomic<uint64_t> value_{0};
};

// One process: every collective is a copy (or nothing).
class LocalComm final : public Comm {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void allgatherv(const void* mine, void* all, const std::vector<uint64_t>& bytes) override {
    if (bytes[0] > 0 && all != mine) std::memmove(all, mine, size_t(bytes[0]));
  }
  void gathervToRoot(const void* mine, void* all, const std::vector<uint64_t>& bytes) override {
    allgatherv(mine, all, bytes);
  }
  void broadcast(void*, uint64_t, int) override {}
  void allreduceSum(uint64_t*, size_t) override {}
  std::unique_ptr<SharedCounter> sharedCounter() override { return std::make_unique<LocalCounter>(); }
  [[noreturn]] void abort(const std::string& message, int code) override {
    std::fprintf(stderr, "%s\n", message.c_str());
    std::fflush(stderr);
    std::_Exit(code);
  }
};

Comm* gWorld = nullptr;  // set by Session while MPI runs

// An integer environment variable, or -1.
int envInt(const char* name) {
  const char* v = std::getenv(name);
  if (!v || !*v) return -1;
  char* end = nullptr;
  long n = std::strtol(v, &end, 10);
  return end && *end == '\0' && n >= 0 && n < (1L << 30) ? int(n) : -1;
}

}  // namespace

std::vector<uint64_t> Comm::allgather(uint64_t value) {
  std::vector<uint64_t> all(static_cast<size_t>(size()));
  allgatherv(&value, all.data(), std::vector<uint64_t>(size_t(size()), sizeof(uint64_t)));
  return all;
}

int Comm::broadcastInt(int value, int from) {
  broadcast(&value, sizeof value, from);
  return value;
}

void raiseIfAnyFailed(Comm& comm, const std::string& localError) {
  if (!comm.distributed()) {
    if (!localError.empty()) throw AgreedError(localError);
    return;
  }
  std::vector<uint64_t> failed = comm.allgather(localError.empty() ? 0 : 1);
  int first = -1;
  for (size_t r = 0; r < failed.size() && first < 0; ++r)
    if (failed[r]) first = int(r);
  if (first < 0) return;
  uint64_t n = first == comm.rank() ? localError.size() : 0;
  comm.broadcast(&n, sizeof n, first);
  std::string message(size_t(n), '\0');
  if (first == comm.rank()) message = localError;
  if (n > 0) comm.broadcast(&message[0], n, first);
  if (first != 0) message = "rank " + std::to_string(first) + ": " + message;
  throw AgreedError(message);
}

Comm& local() {
  static LocalComm one;
  return one;
}

Comm& world() { return gWorld ? *gWorld : local(); }

bool launchedByMpirun(int* size, int* rank) {
  // Open MPI, then MPICH / Intel MPI (PMI), then any PMIx launcher.
  const char* sizes[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
  const char* ranks[] = {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"};
  bool launched = false;
  int n = 1, r = 0;
  for (int i = 0; i < 3; ++i) {
    int s = envInt(sizes[i]), k = envInt(ranks[i]);
    if (s >= 1 || k >= 0) {
      launched = true;
      if (s >= 1) n = s;
      if (k >= 0) r = k;
      break;
    }
  }
  if (size) *size = n;
  if (rank) *rank = r;
  return launched;
}

bool builtWithMpi() {
#ifdef TDPM_MPI
  return true;
#else
  return false;
#endif
}

Session::Session(int& argc, char**& argv) {
  int size = 1, rank = 0;
  if (!launchedByMpirun(&size, &rank)) return;
#ifdef TDPM_MPI
  gWorld = mpi::start(argc, argv);
  started_ = true;
#else
  (void)argc;
  (void)argv;
  if (size > 1) {
    ok_ = false;
    if (rank == 0)
      std::fprintf(stderr,
                   "tdpm: error: started by mpirun as one of %d ranks, but this tdpm was built without MPI "
                   "(TDPM_MPI=OFF): install libopenmpi-dev and rebuild, or run it without mpirun\n",
                   size);
  }
#endif
}

Session::~Session() {
#ifdef TDPM_MPI
  if (started_) {
    gWorld = nullptr;
    mpi::stop();
  }
#endif
}

void testFailurePoint(const Comm& comm, const char* stage) {
  const char* v = std::getenv("TDPM_DIST_TEST_FAIL");
  if (!v || !*v) return;
  std::string spec(v);
  size_t colon = spec.find(':');
  if (colon == std::string::npos) return;
  if (std::atoi(spec.substr(0, colon).c_str()) != comm.rank()) return;
  std::string rest = spec.substr(colon + 1);
  bool crash = false;
  size_t colon2 = rest.find(':');
  if (colon2 != std::string::npos) {
    crash = rest.substr(colon2 + 1) == "crash";
    rest = rest.substr(0, colon2);
  }
  if (rest != stage) return;
  if (crash) _exit(7);
  throw Error(std::string("TDPM_DIST_TEST_FAIL: injected failure at '") + stage + "'");
}

}  // namespace tdpm::dist
