// distributed/comm.h — the processes of a distributed render (docs/distributed.md).
// Owns the one interface the rest of tdpm uses to talk to the other ranks of
// an `mpirun` job: who am I (rank, size), collectives on plain bytes
// (allgather / gather to rank 0 / broadcast / integer sums), agreement on an
// error, and ending the whole job. distributed/mpi_comm.cpp is the only file that
// includes mpi.h; without MPI (TDPM_MPI=OFF, or a plain run without mpirun)
// world() is a one-process Comm whose collectives are copies.
//
// Rules for callers: every rank calls the same collectives in the same
// order with sizes every rank can compute (or has exchanged first). A
// collective only moves bytes: it never adds floats, so results never
// depend on the number of ranks or on the order messages arrive.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"

namespace tdpm::dist {

// What one rank spent on communication: payload bytes it sent (counted
// once per receiving rank) and wall seconds inside collectives, waiting for
// slower ranks included.
struct CommStats {
  uint64_t bytesSent = 0;
  double seconds = 0;
  // CPU time of the calling thread inside collectives: MPI busy-polls while
  // it waits, so a rank waiting for a slower one burns CPU here.
  double cpuSeconds = 0;
};

// A counter every rank of the job shares, for handing out work as it is
// asked for (the tiles of a render: render/tile_loop.h). fetchAdd returns
// the value before adding `n`, atomically over the whole job; any thread of
// a rank may call it. Made by Comm::sharedCounter (collective, value 0) and
// destroyed by every rank at the same point of the program (collective too).
class SharedCounter {
 public:
  virtual ~SharedCounter() = default;
  virtual uint64_t fetchAdd(uint64_t n) = 0;
};

class Comm {
 public:
  virtual ~Comm() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  bool root() const { return rank() == 0; }
  bool distributed() const { return size() > 1; }

  // Every rank's `bytes[rank]` bytes from `mine`, concatenated in rank
  // order into `all` (sum of bytes), on every rank.
  virtual void allgatherv(const void* mine, void* all, const std::vector<uint64_t>& bytes) = 0;
  // The same, delivered to rank 0 only (`all` is ignored elsewhere).
  virtual void gathervToRoot(const void* mine, void* all, const std::vector<uint64_t>& bytes) = 0;
  // `n` bytes of rank `from`, on every rank.
  virtual void broadcast(void* data, uint64_t n, int from) = 0;
  // Element-wise sum over ranks, on every rank (integers: exact).
  virtual void allreduceSum(uint64_t* values, size_t n) = 0;
  // Ends every rank of the job now with exit status `code`, after this
  // rank printed `message` on stderr. For a failure the other ranks cannot
  // know about (they would wait forever in the next collective).
  [[noreturn]] virtual void abort(const std::string& message, int code) = 0;
  // Collective: a new SharedCounter at 0 (held by rank 0; under MPI a
  // one-sided window that the other ranks update without rank 0 taking part).
  virtual std::unique_ptr<SharedCounter> sharedCounter() = 0;

  const CommStats& stats() const { return stats_; }

  // ---- built on the above ----
  // Every rank's value, in rank order.
  std::vector<uint64_t> allgather(uint64_t value);
  int broadcastInt(int value, int from = 0);

 protected:
  CommStats stats_;
};

// Thrown on every rank at once, with the same message, by raiseIfAnyFailed:
// rank 0 reports it, every rank exits 1 (cli/app.cpp).
class AgreedError : public Error {
 public:
  explicit AgreedError(const std::string& message) : Error(message) {}
};

// Collective: `localError` is this rank's error message ("" when it did
// fine). When any rank failed, every rank throws AgreedError with the
// message of the lowest failing rank (named, when it is not rank 0).
void raiseIfAnyFailed(Comm& comm, const std::string& localError);

// [lo, hi) of `total` items for `rank` of `size`: contiguous blocks in rank
// order, so concatenating the blocks in rank order is the original order.
inline void blockRange(uint64_t total, int rank, int size, uint64_t& lo, uint64_t& hi) {
  lo = total * uint64_t(rank) / uint64_t(size);
  hi = total * uint64_t(rank + 1) / uint64_t(size);
}

// Units of an outer loop (progressive passes, animation frames) dealt
// round-robin: rank r runs r, r + size, r + 2 size, ... Round k holds units
// k size .. k size + size - 1, one per rank, in rank order.
inline bool ownsUnit(uint64_t unit, int rank, int size) { return unit % uint64_t(size) == uint64_t(rank); }

// One round of an outer loop whose units are combined in order on rank 0
// (progressive passes: pass k size + r ran on rank r; docs/distributed.md).
// Every rank passes its unit's values (`hasUnit` false for a rank with no
// unit this round, e.g. past the last pass); rank 0 calls add(values,
// count) for each rank that had one, in rank order, which is unit order: the
// same additions in the same order as one process, so bit-identical.
// `mine` must have the same length on every rank that has a unit.
template <class T, class AddUnit>
void combineRoundOnRoot(Comm& comm, const std::vector<T>& mine, bool hasUnit, AddUnit&& add) {
  std::vector<uint64_t> has = comm.allgather(hasUnit ? uint64_t(mine.size()) : 0);
  std::vector<uint64_t> bytes(has.size());
  uint64_t total = 0;
  for (size_t r = 0; r < has.size(); ++r) total += (bytes[r] = has[r] * sizeof(T));
  std::vector<T> all(comm.root() ? size_t(total / sizeof(T)) : 0);
  comm.gathervToRoot(mine.data(), all.data(), bytes);
  if (!comm.root()) return;
  size_t offset = 0;
  for (size_t r = 0; r < has.size(); ++r) {
    if (has[r] > 0) add(all.data() + offset, size_t(has[r]));
    offset += size_t(has[r]);
  }
}

// The Comm of this process: the MPI world under mpirun (after a Session
// started MPI), otherwise one process.
Comm& world();
// A one-process Comm (tests, and every caller that renders alone).
Comm& local();

// Whether a launcher (mpirun / mpiexec of Open MPI, MPICH or any PMIx
// launcher) started this process as one rank of a job, from its environment.
// `size` gets the job's size (1 when unknown).
bool launchedByMpirun(int* size = nullptr, int* rank = nullptr);
// Whether this binary was built with MPI (TDPM_MPI).
bool builtWithMpi();

// Starts MPI for the life of the object when launchedByMpirun() and
// builtWithMpi(); otherwise does nothing, so a plain run never needs a
// launcher. ok() is false (and rank 0 has printed why) when launched as one
// of several ranks by a binary built without MPI: N copies would each
// render the whole image into the same file.
class Session {
 public:
  Session(int& argc, char**& argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_ = true;
  bool started_ = false;
};

// Tests only: TDPM_DIST_TEST_FAIL="RANK:STAGE[:crash]" makes rank RANK fail
// at `STAGE` (throw a tdpm::Error, or with ":crash" end the process with
// status 7 without a word, as a killed rank would). Stages: "load" (scene
// loading), "render" (after the photon maps, before the tiles).
void testFailurePoint(const Comm& comm, const char* stage);

}  // namespace tdpm::dist
