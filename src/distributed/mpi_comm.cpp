// distributed/mpi_comm.cpp — the Comm of an `mpirun` job, on MPI_COMM_WORLD: the
// only file of tdpm that includes mpi.h (compiled only with TDPM_MPI).
// Collectives run on the main thread only; the shared counter of the tile
// queue is called from TBB workers too, one call at a time behind its mutex
// (MPI_THREAD_SERIALIZED).
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <mutex>

#include "distributed/comm.h"
#include "distributed/launcher_link.h"
#include "distributed/mpi_backend.h"

namespace tdpm::dist {

namespace {

// MPI counts are int: larger payloads go in pieces of this many bytes.
constexpr uint64_t kPiece = uint64_t(1) << 30;

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Wall and CPU time of one collective, added to the rank's CommStats.
class Clock {
 public:
  explicit Clock(CommStats& s) : s_(s), start_(std::chrono::steady_clock::now()), cpu_(threadCpuSeconds()) {}
  ~Clock() {
    s_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    s_.cpuSeconds += threadCpuSeconds() - cpu_;
  }

 private:
  CommStats& s_;
  std::chrono::steady_clock::time_point start_;
  double cpu_;
};

// The counter of a work queue: one uint64 in an MPI window on rank 0, read
// and incremented by MPI_Fetch_and_op under a passive-target epoch (lock_all
// for the counter's life), so rank 0 need not serve requests: on one machine
// Open MPI's osc/sm does the atomic add in shared memory. The mutex makes
// the calls of a rank's threads one at a time (MPI_THREAD_SERIALIZED).
class MpiCounter final : public SharedCounter {
 public:
  explicit MpiCounter(CommStats& stats) : stats_(stats) {
    Clock c(stats_);
    int rank = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Win_allocate(rank == 0 ? MPI_Aint(sizeof(uint64_t)) : 0, sizeof(uint64_t), MPI_INFO_NULL, MPI_COMM_WORLD, &base_,
                     &win_);
    if (rank == 0) *base_ = 0;
    MPI_Barrier(MPI_COMM_WORLD);  // rank 0's zero is in place before anyone adds
    MPI_Win_lock_all(0, win_);
  }
  ~MpiCounter() override {
    MPI_Win_unlock_all(win_);
    // MPI_Win_free is collective: when this rank is unwinding an error the
    // others may never get here, and the job is about to be aborted anyway.
    if (std::uncaught_exceptions() == 0) {
      Clock c(stats_);
      MPI_Win_free(&win_);
    }
  }
  uint64_t fetchAdd(uint64_t n) override {
    std::lock_guard<std::mutex> lock(mutex_);
    Clock c(stats_);
    uint64_t old = 0;
    MPI_Fetch_and_op(&n, &old, MPI_UINT64_T, 0, 0, MPI_SUM, win_);
    MPI_Win_flush(0, win_);
    stats_.bytesSent += sizeof n;
    return old;
  }

 private:
  CommStats& stats_;
  std::mutex mutex_;
  MPI_Win win_ = MPI_WIN_NULL;
  uint64_t* base_ = nullptr;
};

class MpiComm final : public Comm {
 public:
  MpiComm() {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  int rank() const override { return rank_; }
  int size() const override { return size_; }

  void allgatherv(const void* mine, void* all, const std::vector<uint64_t>& bytes) override {
    Clock c(stats_);
    stats_.bytesSent += bytes[size_t(rank_)] * uint64_t(size_ - 1);
    std::vector<int> counts, displs;
    if (fitsInt(bytes, counts, displs)) {
      MPI_Allgatherv(mine, counts[size_t(rank_)], MPI_BYTE, all, counts.data(), displs.data(), MPI_BYTE,
                     MPI_COMM_WORLD);
      return;
    }
    // Too large for int counts: each rank broadcasts its block in pieces.
    uint64_t offset = 0;
    for (int r = 0; r < size_; ++r) {
      char* block = static_cast<char*>(all) + offset;
      if (r == rank_ && block != mine) std::copy_n(static_cast<const char*>(mine), size_t(bytes[size_t(r)]), block);
      bcastPieces(block, bytes[size_t(r)], r);
      offset += bytes[size_t(r)];
    }
  }

  void gathervToRoot(const void* mine, void* all, const std::vector<uint64_t>& bytes) override {
    Clock c(stats_);
    if (rank_ != 0) stats_.bytesSent += bytes[size_t(rank_)];
    std::vector<int> counts, displs;
    if (fitsInt(bytes, counts, displs)) {
      MPI_Gatherv(mine, counts[size_t(rank_)], MPI_BYTE, all, counts.data(), displs.data(), MPI_BYTE, 0,
                  MPI_COMM_WORLD);
      return;
    }
    uint64_t offset = 0;
    for (int r = 0; r < size_; ++r) {
      uint64_t n = bytes[size_t(r)];
      if (rank_ == 0 && r == 0) std::copy_n(static_cast<const char*>(mine), size_t(n), static_cast<char*>(all));
      for (uint64_t done = 0; done < n; done += kPiece) {
        int piece = int(std::min(kPiece, n - done));
        if (rank_ == 0 && r != 0)
          MPI_Recv(static_cast<char*>(all) + offset + done, piece, MPI_BYTE, r, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        else if (rank_ == r && r != 0)
          MPI_Send(static_cast<const char*>(mine) + done, piece, MPI_BYTE, 0, 0, MPI_COMM_WORLD);
      }
      offset += n;
    }
  }

  void broadcast(void* data, uint64_t n, int from) override {
    Clock c(stats_);
    if (rank_ == from) stats_.bytesSent += n * uint64_t(size_ - 1);
    bcastPieces(static_cast<char*>(data), n, from);
  }

  void allreduceSum(uint64_t* values, size_t n) override {
    Clock c(stats_);
    stats_.bytesSent += uint64_t(n) * 8 * uint64_t(size_ - 1);
    for (size_t done = 0; done < n; done += size_t(kPiece / 8)) {
      int piece = int(std::min<size_t>(size_t(kPiece / 8), n - done));
      MPI_Allreduce(MPI_IN_PLACE, values + done, piece, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
    }
  }

  std::unique_ptr<SharedCounter> sharedCounter() override { return std::make_unique<MpiCounter>(stats_); }

  [[noreturn]] void abort(const std::string& message, int code) override {
    std::fprintf(stderr, "%s\n", message.c_str());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, code);
    std::_Exit(code);  // MPI_Abort does not return; if it did, still end this rank
  }

 private:
  static bool fitsInt(const std::vector<uint64_t>& bytes, std::vector<int>& counts, std::vector<int>& displs) {
    uint64_t offset = 0;
    for (uint64_t b : bytes) {
      if (b > uint64_t(INT_MAX) || offset > uint64_t(INT_MAX)) return false;
      counts.push_back(int(b));
      displs.push_back(int(offset));
      offset += b;
    }
    return true;
  }
  static void bcastPieces(char* data, uint64_t n, int from) {
    for (uint64_t done = 0; done < n; done += kPiece)
      MPI_Bcast(data + done, int(std::min(kPiece, n - done)), MPI_BYTE, from, MPI_COMM_WORLD);
  }

  int rank_ = 0, size_ = 1;
};

MpiComm* gComm = nullptr;

}  // namespace

namespace mpi {

// Open MPI, every rank of the job on this machine (its launcher says so in
// the environment) and no point-to-point layer chosen by the user
// (OMPI_MCA_pml, set by `--mca pml X` too): select ob1, which talks
// through shared memory (btl vader). Left to itself Open MPI 4.1 also opens
// the cm layer and its InfiniBand/Omni-Path transports (psm, psm2) to
// rank them, and MPI_Init takes about 0.2 s longer (docs/distributed.md).
// On several machines nothing is changed.
void preferSharedMemoryOnOneMachine() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  if (!size || !local || std::strcmp(size, local) != 0) return;
  if (std::getenv("OMPI_MCA_pml")) return;
  setenv("OMPI_MCA_pml", "ob1", 0);
}

Comm* start(int& argc, char**& argv) {
  preferSharedMemoryOnOneMachine();
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided);
  // MPI_Init connected this rank to the launcher's PMIx server: no Nagle on
  // that link, or MPI_Finalize sleeps ~40 ms (distributed/launcher_link.h).
  setNoDelayOnConnectionsTo(pmixServerEndpoints());
  gComm = new MpiComm();
  return gComm;
}

void stop() {
  delete gComm;
  gComm = nullptr;
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

}  // namespace mpi

}  // namespace tdpm::dist
