// tests/test_dist.cpp — the distribution module (distributed/) and the render's
// split of work, without MPI: block ranges of photon batches, the tile
// interleave, pixel sharing with one process, error agreement, launcher
// detection, Nagle off on the link to the launcher. The multi-process runs are in tests/test_dist_mpi.cpp.
#include <doctest/doctest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <tbb/task_arena.h>

#include "distributed/comm.h"
#include "distributed/launcher_link.h"
#include "render/pixel_share.h"
#include "render/tile_loop.h"

using namespace tdpm;

TEST_CASE("dist: block ranges of batches are contiguous, in rank order, and cover everything") {
  for (uint64_t total : {0ull, 1ull, 7ull, 16ull, 391ull, 100003ull})
    for (int size = 1; size <= 9; ++size) {
      uint64_t next = 0, largest = 0, smallest = ~0ull;
      for (int r = 0; r < size; ++r) {
        uint64_t lo = 0, hi = 0;
        dist::blockRange(total, r, size, lo, hi);
        CHECK(lo == next);
        CHECK(hi >= lo);
        largest = std::max(largest, hi - lo);
        smallest = std::min(smallest, hi - lo);
        next = hi;
      }
      CHECK(next == total);
      CHECK(largest - smallest <= 1);  // balanced to one batch
    }
}

TEST_CASE("dist: every tile has exactly one owner, and the shares differ by at most a diagonal") {
  for (int size = 1; size <= 6; ++size)
    for (auto wh : {std::pair<int, int>{1, 1}, {17, 5}, {160, 120}, {333, 47}}) {
      int w = wh.first, h = wh.second;
      size_t tiles = size_t((w + kTileSize - 1) / kTileSize) * size_t((h + kTileSize - 1) / kTileSize);
      std::vector<int> owners(tiles, 0);
      size_t most = 0, least = tiles;
      for (int r = 0; r < size; ++r) {
        std::vector<size_t> mine = ownedTiles(w, h, TileShare{r, size});
        for (size_t i : mine) ++owners[i];
        most = std::max(most, mine.size());
        least = std::min(least, mine.size());
      }
      for (int o : owners) CHECK(o == 1);
      // Diagonal stripes: the counts differ by at most one stripe's length.
      int tilesX = (w + kTileSize - 1) / kTileSize, tilesY = (h + kTileSize - 1) / kTileSize;
      CHECK(most - least <= size_t(std::min(tilesX, tilesY)));
    }
}

TEST_CASE("dist: one process shares pixels as a no-op and its collectives copy") {
  dist::Comm& one = dist::local();
  CHECK(one.rank() == 0);
  CHECK(one.size() == 1);
  CHECK_FALSE(one.distributed());
  std::vector<float> px(40 * 30);
  for (size_t i = 0; i < px.size(); ++i) px[i] = float(i) * 0.5f;
  std::vector<float> before = px;
  sharePixels(one, 40, 30, px, true);
  sharePixels(one, 40, 30, px, false);
  CHECK(px == before);
  std::vector<uint64_t> all = one.allgather(42);
  REQUIRE(all.size() == 1);
  CHECK(all[0] == 42);
  CHECK(one.broadcastInt(5) == 5);
  uint64_t v[2] = {3, 4};
  one.allreduceSum(v, 2);
  CHECK(v[0] == 3);
  CHECK(v[1] == 4);
}

TEST_CASE("dist: an error on one process is raised as the agreed error; no error, nothing raised") {
  dist::Comm& one = dist::local();
  CHECK_NOTHROW(dist::raiseIfAnyFailed(one, ""));
  std::string what;
  try {
    dist::raiseIfAnyFailed(one, "scene.json:3: bad");
  } catch (const dist::AgreedError& e) {
    what = e.what();
  }
  CHECK(what == "scene.json:3: bad");
}

TEST_CASE("dist: a launcher is recognised from its environment, a plain run is not") {
  const char* names[] = {"OMPI_COMM_WORLD_SIZE", "OMPI_COMM_WORLD_RANK", "PMI_SIZE", "PMI_RANK", "PMIX_SIZE", "PMIX_RANK"};
  std::vector<std::pair<std::string, std::string>> saved;
  for (const char* n : names)
    if (const char* v = std::getenv(n)) saved.emplace_back(n, v);
  for (const char* n : names) unsetenv(n);
  int size = -1, rank = -1;
  CHECK_FALSE(dist::launchedByMpirun(&size, &rank));
  CHECK(size == 1);
  CHECK(rank == 0);
  setenv("OMPI_COMM_WORLD_SIZE", "4", 1);
  setenv("OMPI_COMM_WORLD_RANK", "3", 1);
  CHECK(dist::launchedByMpirun(&size, &rank));
  CHECK(size == 4);
  CHECK(rank == 3);
  unsetenv("OMPI_COMM_WORLD_SIZE");
  unsetenv("OMPI_COMM_WORLD_RANK");
  setenv("PMI_SIZE", "2", 1);
  setenv("PMI_RANK", "1", 1);
  CHECK(dist::launchedByMpirun(&size, &rank));
  CHECK(size == 2);
  CHECK(rank == 1);
  unsetenv("PMI_SIZE");
  unsetenv("PMI_RANK");
  for (auto& kv : saved) setenv(kv.first.c_str(), kv.second.c_str(), 1);
}

TEST_CASE("dist: the PMIx server's address is read from the launcher's URI; anything else is refused") {
  dist::TcpEndpoint e;
  REQUIRE(dist::parsePmixServerUri("602996736.0;tcp4://127.0.0.1:51875", e));
  CHECK(e.family == AF_INET);
  CHECK(e.port == 51875);
  CHECK((e.address[0] == 127 && e.address[1] == 0 && e.address[2] == 0 && e.address[3] == 1));
  REQUIRE(dist::parsePmixServerUri("602996736.0;tcp6://[::1]:33127", e));
  CHECK(e.family == AF_INET6);
  CHECK(e.port == 33127);
  CHECK(e.address[15] == 1);
  for (const char* bad : {"", "602996736.0", "602996736.0;tcp4://127.0.0.1", "602996736.0;tcp4://127.0.0.1:0",
                          "602996736.0;tcp4://127.0.0.1:70000", "602996736.0;tcp4://localhost:5", "x;usock://a:5",
                          "602996736.0;tcp4://127.0.0.1:12x"})
    CHECK_MESSAGE(!dist::parsePmixServerUri(bad, e), bad);
}

namespace {
// A listening TCP socket on 127.0.0.1 (ephemeral port) and a client connected to it.
struct LoopbackLink {
  int server = -1, client = -1, accepted = -1;
  dist::TcpEndpoint endpoint;
  LoopbackLink() {
    server = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(bind(server, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
    REQUIRE(listen(server, 1) == 0);
    socklen_t len = sizeof a;
    REQUIRE(getsockname(server, reinterpret_cast<sockaddr*>(&a), &len) == 0);
    client = socket(AF_INET, SOCK_STREAM, 0);
    REQUIRE(connect(client, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
    accepted = accept(server, nullptr, nullptr);
    REQUIRE(accepted >= 0);
    REQUIRE(dist::parsePmixServerUri("1.0;tcp4://127.0.0.1:" + std::to_string(ntohs(a.sin_port)), endpoint));
  }
  ~LoopbackLink() {
    for (int fd : {server, client, accepted})
      if (fd >= 0) close(fd);
  }
  bool noDelay(int fd) const {
    int v = 0;
    socklen_t len = sizeof v;
    return getsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &v, &len) == 0 && v != 0;
  }
};
}  // namespace

TEST_CASE("dist: Nagle is turned off on the connections to the PMIx server, and on no other socket") {
  LoopbackLink pmix, other;
  REQUIRE_FALSE(pmix.noDelay(pmix.client));  // Linux's default: Nagle on
  REQUIRE_FALSE(other.noDelay(other.client));
  // The server's URI as the launcher puts it in the environment.
  const char* names[] = {"PMIX_SERVER_URI41", "PMIX_SERVER_URI4", "PMIX_SERVER_URI3", "PMIX_SERVER_URI21",
                         "PMIX_SERVER_URI2"};
  std::vector<std::pair<std::string, std::string>> saved;
  for (const char* n : names)
    if (const char* v = std::getenv(n)) saved.emplace_back(n, v);
  for (const char* n : names) unsetenv(n);
  CHECK(dist::pmixServerEndpoints().empty());
  const std::string uri = "1.0;tcp4://127.0.0.1:" + std::to_string(pmix.endpoint.port);
  setenv("PMIX_SERVER_URI4", uri.c_str(), 1);
  setenv("PMIX_SERVER_URI3", uri.c_str(), 1);
  std::vector<dist::TcpEndpoint> servers = dist::pmixServerEndpoints();
  for (const char* n : names) unsetenv(n);
  for (auto& kv : saved) setenv(kv.first.c_str(), kv.second.c_str(), 1);
  REQUIRE(servers.size() == 1);  // the same URI twice: one endpoint
  CHECK(servers[0] == pmix.endpoint);

  bool allNoDelay = true;
  CHECK(dist::countConnectionsTo(servers, &allNoDelay) == 1);  // the client end (the accepted end's peer differs)
  CHECK_FALSE(allNoDelay);
  CHECK(dist::setNoDelayOnConnectionsTo(servers) == 1);
  CHECK(pmix.noDelay(pmix.client));
  CHECK_FALSE(pmix.noDelay(pmix.accepted));
  CHECK_FALSE(other.noDelay(other.client));  // another peer: untouched
  CHECK(dist::countConnectionsTo(servers, &allNoDelay) == 1);
  CHECK(allNoDelay);
  CHECK(dist::setNoDelayOnConnectionsTo({}) == 0);
}

TEST_CASE("dist: a round of units is combined on rank 0 in unit order (one process: its own unit)") {
  dist::Comm& one = dist::local();
  std::vector<float> sum(3, 0.0f);
  int calls = 0;
  auto add = [&](const float* v, size_t n) {
    ++calls;
    REQUIRE(n == sum.size());
    for (size_t i = 0; i < n; ++i) sum[i] += v[i];
  };
  dist::combineRoundOnRoot(one, std::vector<float>{1.0f, 2.0f, 3.0f}, true, add);
  dist::combineRoundOnRoot(one, std::vector<float>{0.5f, 0.25f, 0.125f}, true, add);
  dist::combineRoundOnRoot(one, std::vector<float>{9.0f, 9.0f, 9.0f}, false, add);  // no unit: not added
  CHECK(calls == 2);
  CHECK(sum == std::vector<float>{1.5f, 2.25f, 3.125f});
  // Units dealt round-robin: rank r of N owns r, r + N, ...
  for (uint64_t u = 0; u < 20; ++u) {
    int owners = 0;
    for (int r = 0; r < 3; ++r) owners += dist::ownsUnit(u, r, 3);
    CHECK(owners == 1);
    CHECK(dist::ownsUnit(u, int(u % 3), 3));
  }
}

// The tile queue (forEachClaimedTile): two "ranks", each a thread with its
// own TBB loop of 2 workers, take tiles from one shared counter, as ranks
// take them from dist::SharedCounter under MPI. Every tile is rendered
// exactly once, the returned lists are what each rank rendered, and a rank
// that stalls (here: each of its workers in its first tile until the other
// rank is done) keeps only the tiles it had taken: the other does the rest.
TEST_CASE("dist: the tile queue gives every tile to exactly one taker; a stalled taker leaves the rest to the other") {
  const int w = 200, h = 130;  // 13 x 9 tiles, ragged edges
  const size_t total = ownedTiles(w, h, TileShare{}).size();
  std::unique_ptr<dist::SharedCounter> queue = dist::local().sharedCounter();
  std::vector<std::atomic<int>> visits(total);
  std::vector<size_t> lists[2];
  std::atomic<bool> firstDone{false};
  auto rank = [&](int r) {
    tbb::task_arena arena(2);
    arena.execute([&] {
      lists[r] = forEachClaimedTile<int>(w, h, "t", Progress{}, [&](const Tile& t, int&) {
        size_t idx = size_t(t.y0 / kTileSize) * size_t((w + kTileSize - 1) / kTileSize) + size_t(t.x0 / kTileSize);
        visits[idx].fetch_add(1);
        if (r == 1)
          while (!firstDone.load()) std::this_thread::yield();
      }, [&] { return queue->fetchAdd(1); });
    });
  };
  std::thread a(rank, 0), b(rank, 1);
  a.join();
  firstDone = true;
  b.join();
  for (size_t i = 0; i < total; ++i) CHECK(visits[i].load() == 1);
  CHECK(lists[0].size() + lists[1].size() == total);
  CHECK(std::is_sorted(lists[0].begin(), lists[0].end()));
  std::vector<size_t> both = lists[0];
  both.insert(both.end(), lists[1].begin(), lists[1].end());
  std::sort(both.begin(), both.end());
  for (size_t i = 0; i < total; ++i) CHECK(both[i] == i);
  CHECK(lists[1].size() <= 2);  // at most one tile per worker of the stalled rank
  CHECK(lists[0].size() >= total - 2);
  // Gathering pixels by these owners on one process is a no-op; the owners'
  // lists cover the image.
  TileOwners owners = shareTileOwners(dist::local(), both);
  REQUIRE(owners.tiles.size() == 1);
  CHECK(owners.tiles[0].size() == total);
}
