// tests/mpi/dist_selftest.cpp — the collectives of dist::Comm on a real MPI
// job, run by tests/test_dist_mpi.cpp as `mpirun -np 3 tdpm_dist_selftest`:
// uneven allgather / gather, broadcast from a rank other than 0, integer
// sums, error agreement, pixel sharing over the tile interleave, and a
// progressive round combined in rank order with a rank that has no unit,
// and the kd-tree built by the ranks together equal to one built alone;
// and that MPI started with Nagle off on the link to the PMIx server.
// Prints one line per failed check; exit status 0 when every rank passed.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "distributed/comm.h"
#include "distributed/launcher_link.h"
#include "photon/kdtree.h"
#include "render/pixel_share.h"

using namespace tdpm;

namespace {

int failures = 0;

void check(bool ok, const dist::Comm& comm, const char* what) {
  if (ok) return;
  ++failures;
  std::fprintf(stderr, "dist_selftest: rank %d: FAILED: %s\n", comm.rank(), what);
}

}  // namespace

int main(int argc, char** argv) {
  dist::Session session(argc, argv);
  dist::Comm& comm = dist::world();
  const int n = comm.size(), me = comm.rank();
  check(n >= 2, comm, "started by mpirun with at least 2 ranks");

  // Uneven blocks: rank r sends 3 + 7 r values r * 1000 + i.
  auto count = [](int r) { return uint64_t(3 + 7 * r); };
  std::vector<uint32_t> mine(size_t(count(me)));
  for (size_t i = 0; i < mine.size(); ++i) mine[i] = uint32_t(me * 1000 + int(i));
  std::vector<uint64_t> bytes(static_cast<size_t>(n));
  uint64_t total = 0;
  for (int r = 0; r < n; ++r) total += (bytes[size_t(r)] = count(r) * 4) / 4;
  std::vector<uint32_t> expect;
  for (int r = 0; r < n; ++r)
    for (uint64_t i = 0; i < count(r); ++i) expect.push_back(uint32_t(r * 1000 + int(i)));
  std::vector<uint32_t> all(size_t(total), 0);
  comm.allgatherv(mine.data(), all.data(), bytes);
  check(all == expect, comm, "allgatherv of uneven blocks, in rank order");
  std::vector<uint32_t> gathered(size_t(total), 0);
  comm.gathervToRoot(mine.data(), gathered.data(), bytes);
  if (comm.root()) check(gathered == expect, comm, "gathervToRoot of uneven blocks, in rank order");

  // Broadcast from the last rank; sums; allgather of a value.
  uint64_t word = me == n - 1 ? 0x1234567890abcdefull : 0;
  comm.broadcast(&word, sizeof word, n - 1);
  check(word == 0x1234567890abcdefull, comm, "broadcast from the last rank");
  uint64_t sums[2] = {uint64_t(me), 1};
  comm.allreduceSum(sums, 2);
  check(sums[0] == uint64_t(n * (n - 1) / 2) && sums[1] == uint64_t(n), comm, "allreduceSum");
  std::vector<uint64_t> values = comm.allgather(uint64_t(me * me));
  bool valuesOk = values.size() == size_t(n);
  for (int r = 0; valuesOk && r < n; ++r) valuesOk = values[size_t(r)] == uint64_t(r * r);
  check(valuesOk, comm, "allgather of one value per rank");

  // Error agreement: rank 1 fails, every rank hears its message, named.
  std::string heard;
  try {
    dist::raiseIfAnyFailed(comm, me == 1 ? "boom" : "");
  } catch (const dist::AgreedError& e) {
    heard = e.what();
  }
  check(heard == "rank 1: boom", comm, "raiseIfAnyFailed names the failing rank on every rank");
  bool quiet = true;
  try {
    dist::raiseIfAnyFailed(comm, "");
  } catch (const dist::AgreedError&) {
    quiet = false;
  }
  check(quiet, comm, "raiseIfAnyFailed without a failure raises nothing");

  // Pixels: each rank fills its own tiles; afterwards every rank has all.
  const int w = 37, h = 29;
  std::vector<float> px(size_t(w) * size_t(h), NAN);
  TileShare share = tileShareOf(comm);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (share.ownsTileOf(x, y)) px[size_t(y) * w + size_t(x)] = float(y * w + x) + 0.5f;
  std::vector<float> toRoot = px;
  sharePixels(comm, w, h, px, true);
  bool pxOk = true;
  for (size_t i = 0; i < px.size(); ++i) pxOk = pxOk && px[i] == float(i) + 0.5f;
  check(pxOk, comm, "sharePixels to every rank");
  sharePixels(comm, w, h, toRoot, false);
  if (comm.root()) {
    bool rootOk = true;
    for (size_t i = 0; i < toRoot.size(); ++i) rootOk = rootOk && toRoot[i] == float(i) + 0.5f;
    check(rootOk, comm, "sharePixels to rank 0");
  }

  // A progressive round: the last rank has no pass; rank 0 adds the others
  // in rank order (a non-commutative record of the order proves it).
  std::vector<float> unit = {float(me), float(me) * 0.5f};
  std::vector<int> order;
  dist::combineRoundOnRoot(comm, unit, me != n - 1, [&](const float* v, size_t count) {
    if (count == 2 && v[1] == v[0] * 0.5f) order.push_back(int(v[0]));
  });
  if (comm.root()) {
    std::vector<int> want;
    for (int r = 0; r < n - 1; ++r) want.push_back(r);
    check(order == want, comm, "combineRoundOnRoot adds units in rank order and skips a rank without one");
  }

  // The kd-tree built by the ranks together (photon/kdtree.h, options.comm)
  // equals the one built alone, slot for slot: the same photons in the same
  // heap order with the same split axes (in the flags), and the same order.
  // 3D and 4D; a floor of photons with equal y makes ties.
  for (bool spaceTime : {false, true}) {
    photon::PhotonStore alone(0.0f, 1.0f);
    uint64_t state = 12345;
    auto next = [&state] {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      return float(uint32_t(state >> 40)) * 0x1p-24f;
    };
    for (int i = 0; i < 50000; ++i) {
      float x = next() * 10.0f, z = next() * 10.0f, y = i % 3 == 0 ? 0.0f : next() * 4.0f;
      alone.add({x, y, z}, Rgb(1.0f, 0.5f, 0.25f), {0.0f, 1.0f, 0.0f}, next());
    }
    photon::PhotonStore together = alone;
    photon::KdBuildOptions opt;
    opt.spaceTime = spaceTime;
    opt.kappa = 3.0f;
    std::vector<uint32_t> orderAlone, orderTogether;
    opt.order = &orderAlone;
    photon::KdTree::build(alone, opt);
    opt.order = &orderTogether;
    opt.comm = &comm;
    photon::KdTree::build(together, opt);
    auto same = [&](const auto* a, const auto* b) { return std::memcmp(a, b, alone.size() * sizeof(*a)) == 0; };
    check(orderAlone == orderTogether && same(alone.xs(), together.xs()) && same(alone.ys(), together.ys()) &&
              same(alone.zs(), together.zs()) && same(alone.flags(), together.flags()),
          comm, spaceTime ? "4D kd-tree built by the ranks equals the one built alone"
                          : "3D kd-tree built by the ranks equals the one built alone");
  }

  // Session turned Nagle off on this rank's link to the launcher's PMIx
  // server (distributed/launcher_link.h): under Open MPI's mpirun there is one.
  {
    std::vector<dist::TcpEndpoint> servers = dist::pmixServerEndpoints();
    bool allNoDelay = false;
    int links = dist::countConnectionsTo(servers, &allNoDelay);
    if (!servers.empty()) check(links >= 1 && allNoDelay, comm, "TCP_NODELAY on the link to the PMIx server");
  }

  uint64_t failed[1] = {uint64_t(failures)};
  comm.allreduceSum(failed, 1);
  if (comm.root())
    std::printf("dist_selftest: %s on %d ranks\n", failed[0] == 0 ? "every check passed" : "FAILED", n);
  return failed[0] == 0 ? 0 : 1;
}
