// tests/test_grid_file.cpp — media/grid_file.h: OpenVDB .vdb and NanoVDB
// .nvdb density grids written here with the libraries' own API (a ramp of
// known values, so every cell reads back exactly), and every refusal the
// reader makes, each a located error. Built with OpenVDB's flags alone
// (tests/CMakeLists.txt).
#include <doctest/doctest.h>

#include <cmath>
#include <fstream>
#include <limits>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include "cli_harness.h"
#include "core/error.h"
#include "media/grid_file.h"

using namespace tdpm;

namespace {

constexpr uint64_t kPlenty = uint64_t(1) << 30;

// A distinct value per voxel: i + 10 j + 100 k + 1000 (all > 0).
float ramp(int i, int j, int k) { return float(i + 10 * j + 100 * k + 1000); }

// Voxels [2, 5] x [-1, 1] x [0, 2] set to ramp(), voxel sizes `vs`,
// translated by `t`; the grid is named `name`.
openvdb::FloatGrid::Ptr rampGrid(const std::string& name, openvdb::Vec3d vs = {0.5, 0.5, 0.5},
                                 openvdb::Vec3d t = {1, 2, 3}) {
  openvdb::initialize();
  openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
  g->setName(name);
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.setToScale(vs);
  m.setTranslation(t);
  g->setTransform(openvdb::math::Transform::createLinearTransform(m));
  auto acc = g->getAccessor();
  for (int k = 0; k <= 2; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = 2; i <= 5; ++i) acc.setValue(openvdb::Coord(i, j, k), ramp(i, j, k));
  g->setGridClass(openvdb::GRID_FOG_VOLUME);
  return g;
}

void writeVdb(const std::string& path, openvdb::GridPtrVec grids) { openvdb::io::File(path).write(grids); }

scene::DensityGridDesc gridDesc(const std::string& file, const std::string& name = "density") {
  scene::DensityGridDesc g;
  g.file = file;
  g.gridName = name;
  return g;
}

std::string loadError(const std::string& file, const std::string& name = "density", uint64_t maxBytes = kPlenty) {
  scene::DensityGridDesc g = gridDesc(file, name);
  try {
    media::loadDensityGridFile(g, "scene.json: media.smoke", maxBytes);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

void checkRamp(const scene::DensityGridDesc& g, openvdb::Vec3d vs = {0.5, 0.5, 0.5}, openvdb::Vec3d t = {1, 2, 3}) {
  REQUIRE(g.nx == 4);
  REQUIRE(g.ny == 3);
  REQUIRE(g.nz == 3);
  REQUIRE(g.density.size() == 36);
  size_t n = 0;
  for (int k = 0; k <= 2; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = 2; i <= 5; ++i) CHECK(g.density[n++] == ramp(i, j, k));  // x fastest, exact
  // The box the cells tile: half a voxel past the outer voxel centres.
  CHECK(g.bounds.lo.x == float(t[0] + vs[0] * 1.5));
  CHECK(g.bounds.hi.x == float(t[0] + vs[0] * 5.5));
  CHECK(g.bounds.lo.y == float(t[1] + vs[1] * -1.5));
  CHECK(g.bounds.hi.y == float(t[1] + vs[1] * 1.5));
  CHECK(g.bounds.lo.z == float(t[2] + vs[2] * -0.5));
  CHECK(g.bounds.hi.z == float(t[2] + vs[2] * 2.5));
}

}  // namespace

TEST_CASE("an OpenVDB float grid reads back dense, every cell exact, bounds the world box of its cells") {
  std::string dir = test::makeTempDir(), f = dir + "/ramp.vdb";
  writeVdb(f, {rampGrid("temperature"), rampGrid("density")});
  scene::DensityGridDesc g = gridDesc(f);
  media::loadDensityGridFile(g, "scene.json: media.smoke", kPlenty);
  checkRamp(g);
  // Another grid of the file, by name; a non-uniform voxel size is still axis aligned.
  writeVdb(f, {rampGrid("smoke", {0.25, 1, 2}, {-1, 0, 5})});
  scene::DensityGridDesc s = gridDesc(f, "smoke");
  media::loadDensityGridFile(s, "scene.json: media.smoke", kPlenty);
  checkRamp(s, {0.25, 1, 2}, {-1, 0, 5});
}

TEST_CASE("inactive voxels inside the active box read as the grid holds them (background 0)") {
  std::string dir = test::makeTempDir(), f = dir + "/sparse.vdb";
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->tree().setValue(openvdb::Coord(0, 0, 0), 2.0f);
  grid->tree().setValue(openvdb::Coord(2, 1, 0), 3.0f);
  writeVdb(f, {grid});
  scene::DensityGridDesc g = gridDesc(f);
  media::loadDensityGridFile(g, "scene.json: media.smoke", kPlenty);
  REQUIRE((g.nx == 3 && g.ny == 2 && g.nz == 1));
  CHECK(g.density == std::vector<float>{2, 0, 0, 0, 0, 3});
  CHECK(g.bounds.lo.x == -0.5f);  // OpenVDB's default transform: unit voxels at the origin
  CHECK(g.bounds.hi.x == 2.5f);
}

TEST_CASE("a NanoVDB float grid (made from the same OpenVDB grid) reads back the same cells") {
  std::string dir = test::makeTempDir(), f = dir + "/ramp.nvdb";
  // A full checksum, so that a changed voxel byte is caught (the default
  // checksum covers the headers only).
  auto handle = nanovdb::openToNanoVDB(*rampGrid("density"), nanovdb::StatsMode::Default, nanovdb::ChecksumMode::Full);
  nanovdb::io::writeGrid(f, handle);
  scene::DensityGridDesc g = gridDesc(f);
  media::loadDensityGridFile(g, "scene.json: media.smoke", kPlenty);
  checkRamp(g);
  CHECK(loadError(f, "heat").find("has no grid named \"heat\" (its grids: \"density\")") != std::string::npos);
  // Damaged: cut short, and one byte of the grid changed (the checksum refuses it).
  std::ifstream in(f, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  test::writeFile(dir + "/short.nvdb", bytes.substr(0, bytes.size() / 2));
  std::string e = loadError(dir + "/short.nvdb");
  CHECK(e.find("scene.json: media.smoke: density grid file \"" + dir + "/short.nvdb\"") == 0);
  CHECK(e.find("truncated") != std::string::npos);
  std::string flipped = bytes;
  flipped[flipped.size() - 40] = char(flipped[flipped.size() - 40] ^ 0x5a);
  test::writeFile(dir + "/flipped.nvdb", flipped);
  e = loadError(dir + "/flipped.nvdb");
  CHECK(e.find("damaged") != std::string::npos);
}

TEST_CASE("grid files: every refusal is located and says what is wrong") {
  std::string dir = test::makeTempDir();
  const std::string at = "scene.json: media.smoke: density grid file \"";
  SUBCASE("missing file") {
    std::string e = loadError(dir + "/none.vdb");
    CHECK(e.find(at + dir + "/none.vdb\"") == 0);
    CHECK(e.find("does not exist") != std::string::npos);
  }
  SUBCASE("not a VDB") {
    test::writeFile(dir + "/text.vdb", "this is not a grid\n");
    std::string e = loadError(dir + "/text.vdb");
    CHECK(e.find(at) == 0);
    CHECK(e.find("not a readable OpenVDB file") != std::string::npos);
  }
  SUBCASE("no grid of that name: the grids present are listed") {
    writeVdb(dir + "/g.vdb", {rampGrid("temperature"), rampGrid("smoke")});
    std::string e = loadError(dir + "/g.vdb");
    CHECK(e.find("has no grid named \"density\" (its grids: ") != std::string::npos);
    CHECK(e.find("\"temperature\"") != std::string::npos);
    CHECK(e.find("\"smoke\"") != std::string::npos);
  }
  SUBCASE("not a float grid") {
    openvdb::initialize();
    openvdb::Vec3SGrid::Ptr v = openvdb::Vec3SGrid::create();
    v->setName("density");
    v->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 2, 3));
    writeVdb(dir + "/v.vdb", {v});
    std::string e = loadError(dir + "/v.vdb");
    CHECK(e.find("grid \"density\": is a vec3s grid; a density grid must hold floats") != std::string::npos);
  }
  SUBCASE("empty grid") {
    openvdb::initialize();
    openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    writeVdb(dir + "/e.vdb", {g});
    CHECK(loadError(dir + "/e.vdb").find("the grid is empty (no active voxels)") != std::string::npos);
  }
  SUBCASE("too large: dimensions and bytes named, before allocation") {
    writeVdb(dir + "/r.vdb", {rampGrid("density")});
    std::string e = loadError(dir + "/r.vdb", "density", 100);
    CHECK(e.find("4 x 3 x 3 cells, 144 bytes as a dense grid, more than the 100 bytes allowed") != std::string::npos);
    // A huge sparse grid (two voxels far apart) is refused by its box, not by what it stores.
    openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
    g->setName("density");
    g->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    g->tree().setValue(openvdb::Coord(100000, 100000, 100000), 1.0f);
    writeVdb(dir + "/huge.vdb", {g});
    e = loadError(dir + "/huge.vdb");
    CHECK(e.find("100001 x 100001 x 100001 cells") != std::string::npos);
  }
  SUBCASE("negative and non-finite densities") {
    for (float bad : {-0.5f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
      openvdb::FloatGrid::Ptr g = rampGrid("density");
      g->tree().setValue(openvdb::Coord(3, 0, 1), bad);
      writeVdb(dir + "/n.vdb", {g});
      std::string e = loadError(dir + "/n.vdb");
      CHECK(e.find("voxel (3, 0, 1) has density ") != std::string::npos);
      CHECK(e.find("densities must be finite and >= 0") != std::string::npos);
    }
  }
  SUBCASE("a rotated grid transform is refused (not silently axis aligned)") {
    openvdb::FloatGrid::Ptr g = rampGrid("density");
    g->transform().preRotate(0.3, openvdb::math::Z_AXIS);
    writeVdb(dir + "/rot.vdb", {g});
    CHECK(loadError(dir + "/rot.vdb").find("rotates or shears the voxels") != std::string::npos);
  }
}
