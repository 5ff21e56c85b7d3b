// tests/test_scenes.cpp — the shipped scenes (scenes/*.json): every file
// parses and builds, the paper's scenes are all there, and only static-room
// is free of motion (it exists to exercise the no-motion path).
#include <doctest/doctest.h>

#include <dirent.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "scene/parse.h"
#include "scene/scene.h"

using namespace tdpm;

namespace {

const std::string kScenes = std::string(TDPM_SOURCE_DIR) + "/scenes";

std::vector<std::string> sceneFiles() {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(kScenes.c_str())) {
    while (dirent* e = ::readdir(d)) {
      std::string n = e->d_name;
      if (n.size() > 5 && n.compare(n.size() - 5, 5, ".json") == 0) names.push_back(n);
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("scenes: the paper's scenes are all shipped") {
  std::vector<std::string> files = sceneFiles();
  std::set<std::string> have(files.begin(), files.end());
  for (std::string name : {"glass-ball.json", "cube-caustic.json", "truck-laser.json", "car-following.json",
                           "static-room.json"})
    CHECK_MESSAGE(have.count(name) == 1, "missing scenes/" << name);
}

TEST_CASE("scenes: every scenes/*.json loads and builds; only static-room is static") {
  std::vector<std::string> files = sceneFiles();
  REQUIRE(!files.empty());
  for (const std::string& name : files) {
    CAPTURE(name);
    std::unique_ptr<Scene> scene;
    try {
      scene::SceneDescription desc = scene::loadScene(kScenes + "/" + name);
      scene = Scene::build(desc);
    } catch (const std::exception& e) {
      FAIL_CHECK(name << ": " << e.what());
      continue;
    }
    REQUIRE(scene != nullptr);
    CHECK(!scene->objects.empty());
    CHECK(!scene->lights.empty());
    if (name == "static-room.json")
      CHECK_FALSE(scene->hasMotion);
    else
      CHECK(scene->hasMotion);
  }
}
