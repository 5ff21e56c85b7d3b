// tests/test_memory.cpp — memory-footprint tests: bytes per photon (store +
// kd-tree) at 1M and 10M photons, the pre-flight photon-memory estimate and
// its error, the peak resident memory of a 10M-caustic-photon render (run
// as its own process, so the peak is that render's alone) against a budget
// derived from the bytes per photon, and an impossible budget failing fast.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "cli_harness.h"
#include "core/error.h"
#include "core/memory.h"
#include "core/rng.h"
#include "photon/kdtree.h"
#include "photon/store.h"
#include "render/memory_budget.h"
#include "render/renderer.h"

using namespace tdpm;
using photon::KdTree;
using photon::PhotonStore;

namespace {

// A store filled the way photon/tracer.cpp fills one: per-thread batches of
// a few hundred photons (no reserve, so they carry push_back slack), then
// appendBatches and shrinkToFit. Positions on a floor and a wall, with a
// dense caustic-like cluster, so the kd-tree sees realistic structure.
PhotonStore tracedLikeStore(size_t n, uint64_t seed) {
  const size_t perBatch = 250;
  std::vector<PhotonStore> batches;
  batches.reserve(n / perBatch + 1);
  Rng rng(seed);
  for (size_t done = 0; done < n; done += perBatch) {
    batches.emplace_back(0.0f, 1.0f);
    PhotonStore& b = batches.back();
    for (size_t i = 0; i < perBatch && done + i < n; ++i) {
      float c = rng.uniform();
      Vec3f p = c < 0.6f   ? Vec3f{rng.uniform() * 4 - 2, 0.0f, rng.uniform() * 4 - 2}
                : c < 0.8f ? Vec3f{rng.uniform() * 4 - 2, rng.uniform() * 3, -2.0f}
                           : Vec3f{0.3f + 0.05f * rng.uniform(), 0.0f, 0.2f + 0.05f * rng.uniform()};
      b.add(p, Rgb(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-6f, {0, 1, 0}, rng.uniform());
    }
  }
  PhotonStore all(0.0f, 1.0f);
  all.appendBatches(batches);
  all.shrinkToFit();
  return all;
}

void checkBytesPerPhoton(size_t n, bool spaceTime) {
  PhotonStore s = tracedLikeStore(n, 17 + n);
  REQUIRE(s.size() == n);
  photon::KdBuildOptions opt;
  opt.spaceTime = spaceTime;
  KdTree tree = KdTree::build(s, opt);
  double perPhoton = double(s.bytesAllocated()) / double(n);
  std::string what = spaceTime ? " (4D tree)" : "";
  MESSAGE(n << " photons" << what << ": " << perPhoton
          << " bytes per photon after KdTree::build");
  CHECK(perPhoton <= 20.0);
  CHECK(tree.bytesPerPhoton() <= 20.0);
  CHECK(tree.size() == n);
}

// "peak resident memory: <bytes> bytes" from `tdpm render --stats`; 0 if absent.
uint64_t parsePeak(const std::string& output) {
  const char* key = "peak resident memory: ";
  size_t at = output.find(key);
  if (at == std::string::npos) return 0;
  return std::strtoull(output.c_str() + at + std::strlen(key), nullptr, 10);
}

uint64_t parseStored(const std::string& output) {
  const char* key = "caustic photons: ";
  size_t at = output.find(key);
  if (at == std::string::npos) return 0;
  return std::strtoull(output.c_str() + at + std::strlen(key), nullptr, 10);
}

// A point light just above a glass sphere over a diffuse floor: about a
// quarter of the emitted paths pass through the sphere and store a caustic
// photon, so 10M photons take ~42M paths (~15 s on 2 cores).
const char* kCausticScene = R"({
  "camera": {"position": [0, 3, 4], "target": [0, 0, 0], "fov": 40, "resolution": [16, 16], "shutter": [0, 1]},
  "materials": {"glass": {"type": "dielectric", "ior": 1.5}, "floor": {"type": "diffuse", "color": [0.7, 0.7, 0.7]}},
  "objects": [
    {"name": "floor", "shape": {"type": "quad", "size": [20, 20]}, "material": "floor"},
    {"name": "ball", "shape": {"type": "sphere", "radius": 1}, "material": "glass", "transform": {"translate": [0, 1.5, 0]}}
  ],
  "lights": [{"name": "lamp", "type": "point", "position": [0, 2.6, 0], "power": [100, 100, 100]}]
})";

// The budget of the peak-RSS test, per stored caustic photon: the larger of
// tracing (the store + its shrink-to-fit copy, 2 x 20; the chunk of batch
// buffers is a constant, inside kBaseSlack) and the kd-tree build (20 bytes
// of store + 21 of builder records), with 7 bytes for the allocator.
// Measured: 41.1 bytes per photon above the 0-photon base at 10M (61.4
// before photon/tracer.cpp appended batches in chunks).
constexpr double kBudgetBytesPerPhoton = 48.0;
// Fixed allowance on top of the measured 0-photon base (allocator arenas of
// the tracing threads, the film, page-granularity noise).
constexpr uint64_t kBaseSlack = uint64_t(32) << 20;

// Under AddressSanitizer (-DTDPM_SANITIZE=ON) the allocator adds redzones,
// a quarantine of freed blocks and shadow memory: the peak is not the
// renderer's, so the budget is not asserted, and 1M photons keep it short.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

}  // namespace

TEST_CASE("memory: peak and available memory are read from /proc") {
  uint64_t now = currentResidentBytes();
  uint64_t peak = peakResidentBytes(), avail = availableMemoryBytes();
  CHECK(peak > 0);
  CHECK(now > 0);
  CHECK(peak >= now);
  CHECK(avail > 0);
  // Touching 64 MiB raises the high-water mark by about that much.
  std::vector<char> block(size_t(64) << 20);
  std::memset(block.data(), 1, block.size());
  CHECK(peakResidentBytes() >= now + (uint64_t(60) << 20));
  CHECK(block[12345] == 1);
}

TEST_CASE("memory: at most 20 bytes per photon (store + kd-tree) at 1M and 10M photons") {
  checkBytesPerPhoton(1000000, false);
  checkBytesPerPhoton(1000000, true);  // the 4D tree also lives in the store's flag bits
  checkBytesPerPhoton(10000000, false);
}

TEST_CASE("memory: the pre-flight photon estimate and its error") {
  const uint64_t n = 10000000;
  const uint64_t chunkPaths = 256 * 1024;  // photon/tracer.cpp: 256 batches of 1024 paths
  // 3D caustic only: tracing holds the store and its shrink-to-fit copy
  // (2 x 20 bytes) plus one chunk of batch buffers (40 bytes a photon, one
  // photon a caustic path); just above the kd-tree build's 20 + 21.
  CHECK(photonMemoryBytes({n, 0}, false, 16) == n * 40 + chunkPaths * 40);
  // 4D: the 3D copy is held while the 4D tree is built: 2 x 20 + 25.
  CHECK(photonMemoryBytes({n, 0}, true, 16) == n * 65);
  // The global map is traced while the caustic map is held; a global path
  // stores up to max_depth + 1 photons, so its chunk is 17 times larger.
  CHECK(photonMemoryBytes({n, n}, false, 16) == n * 20 + n * 40 + chunkPaths * 17 * 40);
  CHECK(photonMemoryBytes({n, n}, true, 16) == n * 40 + n * 65);
  // No photons: nothing (the pilot only runs for a map that is traced).
  CHECK(photonMemoryBytes({0, 0}, false, 16) == 0);
  // A tiny global map still pays for the pilot (16K paths, up to 17 photons each).
  CHECK(photonMemoryBytes({0, 1}, false, 16) == uint64_t(16 * 1024) * 17 * 60);

  const uint64_t avail = uint64_t(8) << 30;  // 8 GiB
  CHECK_NOTHROW(checkPhotonMemory({n, n}, true, 16, avail, {"--photons", "--global-photons"}));
  // Unknown availability (no /proc): never refuse.
  CHECK_NOTHROW(checkPhotonMemory({size_t(1) << 31, size_t(1) << 31}, true, 16, 0, {"--photons", "--global-photons"}));

  auto message = [&](size_t c, size_t g, bool st) {
    try {
      checkPhotonMemory({c, g}, st, 16, avail, {"--photons", "render.global_photons in s.json"});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string m = message(size_t(2000000000), 1000, false);
  MESSAGE(m);
  CHECK(m.find("--photons asks for 2000000000 caustic photons") != std::string::npos);
  // 2e9 x 41 bytes: at that size the kd-tree build (20 + 21) outweighs
  // tracing (2 x 20 + one chunk of batch buffers).
  CHECK(m.find("82000000000 bytes") != std::string::npos);
  CHECK(m.find(std::to_string(avail - memoryMarginBytes(avail)) + " bytes") != std::string::npos);
  CHECK(m.find("MemAvailable 8589934592 bytes") != std::string::npos);
  m = message(1000, size_t(1) << 31, false);
  CHECK(m.find("render.global_photons in s.json asks for 2147483648 global photons") != std::string::npos);
  // Each fits alone, not together: both are named.
  m = message(size_t(80000000), size_t(80000000), true);
  CHECK(m.find("--photons and render.global_photons in s.json ask for") != std::string::npos);
  CHECK(m.find("--search 4d") != std::string::npos);
}

TEST_CASE("memory: peak resident memory of a 10M-caustic-photon render stays within its budget") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/caustic.json", kCausticScene);
  const std::string common = "render '" + dir + "/caustic.json' -m time --spp 1 --gather 0 --global-photons 0 -t 2 --stats";

  // The fixed base: the same render without photons (scene, Embree, TBB, film).
  test::CommandResult base = test::runTdpm(common + " --photons 0 -o '" + dir + "/base.exr'");
  REQUIRE(base.exitCode == 0);
  uint64_t basePeak = parsePeak(base.output);
  REQUIRE(basePeak > 0);

  const uint64_t wanted = kSanitized ? 1000000 : 10000000;
  test::CommandResult r = test::runTdpm(common + " --photons " + std::to_string(wanted) + " -o '" + dir + "/big.exr'");
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  uint64_t peak = parsePeak(r.output), stored = parseStored(r.output);
  // The stats block lists every figure it promises.
  for (const char* line : {"bytes per photon: 20.00", "global photons: 0 stored, 0 emitted", "photon pass: ",
                           "render: ", "estimates: ", "samples per pixel: 1-1"})
    CHECK(r.output.find(line) != std::string::npos);
  REQUIRE(stored > wanted * 99 / 100);  // storedWanted is reached up to noise
  REQUIRE(stored < wanted * 101 / 100);
  // The figure is real: the maps' own 20 bytes per photon are in it.
  CHECK(peak >= basePeak + stored * 20);
  if (kSanitized) return;

  double perPhoton = double(peak - basePeak) / double(stored);
  uint64_t budget = basePeak + kBaseSlack + uint64_t(kBudgetBytesPerPhoton * double(stored));
  MESSAGE("0-photon base " << basePeak / 1048576.0 << " MiB; " << stored << " photons: peak " << peak / 1048576.0
                           << " MiB = base + " << perPhoton << " bytes per photon; budget " << budget / 1048576.0
                           << " MiB (base + 32 MiB + " << kBudgetBytesPerPhoton << " B/photon)");
  CHECK(peak <= budget);
  // The pre-flight estimate the renderer checks against MemAvailable is an
  // upper bound of what the photon pass really took (up to the base slack).
  CHECK(peak <= basePeak + kBaseSlack + photonMemoryBytes({stored, 0}, false, 16));
}

TEST_CASE("memory: a photon budget that cannot fit fails before any work, with the flag and the bytes") {
  std::string dir = test::makeTempDir();
  test::writeFile(dir + "/caustic.json", kCausticScene);
  test::CommandResult r = test::runTdpm("render '" + dir + "/caustic.json' -o '" + dir +
                                        "/out.exr' --photons 2000000000 --global-photons 2000000000");
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("tdpm: error: --photons asks for 2000000000 caustic photons") != std::string::npos);
  CHECK(r.output.find("bytes") != std::string::npos);
  CHECK(r.output.find("MemAvailable") != std::string::npos);
  CHECK(test::countEntries(dir) == 1);  // the scene only: no EXR, no PNG

  // Set in the scene file: the error names the key and the file.
  std::string scene = kCausticScene;
  scene.insert(scene.rfind('}'), R"(, "render": {"photons": 1000, "global_photons": 2147483648})");
  test::writeFile(dir + "/scene-budget.json", scene);
  r = test::runTdpm("render '" + dir + "/scene-budget.json' -o '" + dir + "/out.exr' --gather 1");
  INFO(r.output);
  CHECK(r.exitCode == 1);
  CHECK(r.output.find("render.global_photons in " + dir + "/scene-budget.json asks for 2147483648 global photons") !=
        std::string::npos);
  CHECK(test::countEntries(dir) == 2);

  // Above 2^31 is refused by the flag parser itself (usage error, exit 2).
  r = test::runTdpm("render '" + dir + "/caustic.json' -o '" + dir + "/out.exr' --photons 2147483649");
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--photons") != std::string::npos);
  CHECK(test::countEntries(dir) == 2);
}

TEST_CASE("memory: an animation block's kept path states are checked against the memory available") {
  const uint64_t GiB = uint64_t(1) << 30;
  // 10M paths of 56 bytes = 560 MB: fits 8 GiB, not 512 MiB (margin 256 MiB + 1/16).
  CHECK_NOTHROW(checkKeptStatesMemory(10000000, 56, 0, 8 * GiB, 4));
  std::string e;
  try {
    checkKeptStatesMemory(10000000, 56, 0, GiB / 2, 4);
  } catch (const std::exception& ex) {
    e = ex.what();
  }
  INFO(e);
  CHECK(e.find("block of 4 frames traces 10000000 photon paths") != std::string::npos);
  CHECK(e.find("--no-continue-paths") != std::string::npos);
  CHECK(e.find("MemAvailable") != std::string::npos);
  // What the block already holds counts: 1.2 GiB of states held tip 1.5 GiB (usable 1184 MiB), 1 GiB does not.
  CHECK_NOTHROW(checkKeptStatesMemory(1000000, 56, 0, 3 * GiB / 2, 4));
  CHECK_THROWS(checkKeptStatesMemory(1000000, 56, GiB + GiB / 5, 3 * GiB / 2, 4));
  CHECK_NOTHROW(checkKeptStatesMemory(1000000, 56, GiB, 3 * GiB / 2, 4));
  CHECK_NOTHROW(checkKeptStatesMemory(uint64_t(1) << 40, 56, 0, 0, 4));  // unknown memory: no check
}

TEST_CASE("memory: progressive frames sharing a block hold every frame's state, checked against the memory available") {
  const uint64_t GiB = uint64_t(1) << 30;
  // 3840x2160 at 7 float layers = 232 MB a frame: 4 fit 2 GiB, 16 do not.
  const uint64_t frame = uint64_t(3840) * 2160 * 7 * 4;
  CHECK_NOTHROW(checkBlockStatesMemory(4, frame, 2 * GiB, 4));
  std::string e;
  try {
    checkBlockStatesMemory(16, frame, 2 * GiB, 16);
  } catch (const std::exception& ex) {
    e = ex.what();
  }
  INFO(e);
  CHECK(e.find("states of 16 frames at once (--window 16") != std::string::npos);
  CHECK(e.find("--shared-photons 0") != std::string::npos);
  CHECK_NOTHROW(checkBlockStatesMemory(uint64_t(1) << 20, frame, 0, 4));  // unknown memory: no check
}
