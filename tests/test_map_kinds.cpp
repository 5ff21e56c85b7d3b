// tests/test_map_kinds.cpp — the photon maps by kind (render/map_kinds.h):
// the one table keeps the names users and tests read (--stats, --json, the
// EXR metadata, the progressive state), each kind's request comes from its
// own option, and the per-kind memory model is the two-map formula it
// replaced (each map traced while the ones before it are held).
#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <string>

#include "cli/render_metadata.h"
#include "render/map_kinds.h"
#include "render/memory_budget.h"
#include "render/photon_map.h"

using namespace tdpm;

TEST_CASE("map kinds: the table is in enum order and keeps the names on disk") {
  std::set<std::string> names, options;
  for (size_t i = 0; i < kMapKinds; ++i) {
    const MapKindInfo& row = mapKindInfo(kAllMapKinds[i]);
    CHECK(size_t(row.kind) == i);
    names.insert(row.name);
    options.insert(row.optionName);
  }
  CHECK(names.size() == kMapKinds);
  CHECK(options.size() == kMapKinds);
  // Users' scripts and resumed states read these exact names.
  CHECK(std::string(mapKindName(MapKind::Caustic)) == "caustic");
  CHECK(std::string(mapKindName(MapKind::Global)) == "global");
  CHECK(std::string(mapKindInfo(MapKind::Caustic).optionName) == "photons");
  CHECK(std::string(mapKindInfo(MapKind::Global).optionName) == "global_photons");
}

TEST_CASE("map kinds: each kind's request is its own option, and no global map without a gather") {
  RenderOptions o;
  o.causticPhotons = 123;
  o.globalPhotons = 45;
  o.gatherRays = 1;
  PerMap<size_t> w = photonsWanted(o);
  CHECK(w[MapKind::Caustic] == 123);
  CHECK(w[MapKind::Global] == 45);
  o.gatherRays = 0;
  CHECK(photonsWanted(o)[MapKind::Global] == 0);
  o.visualizeGlobal = true;
  CHECK(photonsWanted(o)[MapKind::Global] == 45);
  CHECK(o.*mapKindInfo(MapKind::Global).photonsSource == "--global-photons");
}

TEST_CASE("map kinds: the metadata names every kind's stored photons") {
  RenderOptions o;
  o.method = RenderMethod::Standard;
  RenderStats st;
  st.maps[MapKind::Caustic].stored = 7;
  st.maps[MapKind::Global].stored = 9;
  auto m = cli::renderMetadata("s.json", o, st);
  CHECK(m.at("tdpm/caustic_photons") == "7");
  CHECK(m.at("tdpm/global_photons") == "9");
}

TEST_CASE("map kinds: the memory model holds the maps before the one being traced") {
  // Each map alone, and the pair: the pair is the worse of the caustic map
  // alone and the caustic map kept while the global one is traced.
  for (bool st4 : {false, true})
    for (size_t c : {size_t(0), size_t(1000), size_t(5000000)})
      for (size_t g : {size_t(0), size_t(300), size_t(2000000)}) {
        uint64_t alone = photonMemoryBytes({c, 0}, st4, 16);
        uint64_t globalAlone = photonMemoryBytes({0, g}, st4, 16);
        uint64_t kept = uint64_t(c) * 20 * (st4 ? 2 : 1);
        CHECK(photonMemoryBytes({c, g}, st4, 16) == std::max(alone, kept + globalAlone));
      }
}

TEST_CASE("map kinds: the volume map is named only where it is traced") {
  CHECK(std::string(mapKindName(MapKind::Volume)) == "volume");
  CHECK(std::string(mapKindInfo(MapKind::Volume).optionName) == "volume_photons");
  RenderOptions o;
  o.method = RenderMethod::Time;
  RenderStats st;
  // No media (volumePhotons 0): no key, as before the kind existed.
  auto m = cli::renderMetadata("s.json", o, st);
  CHECK(m.count("tdpm/volume_photons") == 0);
  CHECK(m.count("tdpm/caustic_photons") == 1);
  CHECK(!mapKindReported(MapKind::Volume, st.maps[MapKind::Volume]));
  CHECK(mapKindReported(MapKind::Global, st.maps[MapKind::Global]));
  o.volumePhotons = 10;
  st.maps[MapKind::Volume].stored = 11;
  st.maps[MapKind::Volume].emitted = 4096;
  m = cli::renderMetadata("s.json", o, st);
  CHECK(m.at("tdpm/volume_photons") == "11");
  CHECK(mapKindReported(MapKind::Volume, st.maps[MapKind::Volume]));
  CHECK(photonsWanted(o)[MapKind::Volume] == 10);
}
