// media/grid_file.cpp — density grids from files (see grid_file.h): which
// reader a file needs (by its first bytes: NanoVDB's magic number, else
// OpenVDB, whose reader says when the file is neither). NanoVDB's reader is
// header-only and built in (grid_file_nanovdb.cpp). OpenVDB's is a module,
// libtdpm_openvdb.so (grid_file_openvdb.cpp), opened the first time a .vdb
// is read: linking libopenvdb into tdpm made every run start 0.1 s later
// (its static initialisers; `tdpm --version` 0.02 s -> 0.11 s, measured with
// /usr/bin/time here), scenes without grid files included.
#include "media/grid_file.h"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "core/error.h"
#include "core/regular_file.h"
#include "media/grid_readers.h"

namespace tdpm::media {

namespace {

constexpr const char* kModule = "libtdpm_openvdb.so";

// Where the module is looked for: $TDPM_OPENVDB_MODULE (a path; then only
// there), else beside the running executable and the build folder it was
// built in.
std::vector<std::string> moduleCandidates() {
  std::vector<std::string> out;
  if (const char* env = std::getenv("TDPM_OPENVDB_MODULE"); env && *env) return {env};
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back((exe.parent_path() / kModule).string());
    out.push_back((exe.parent_path().parent_path() / kModule).string());  // build/tests/tdpm_tests -> build/
  }
#ifdef TDPM_MODULE_DIR
  out.push_back(std::string(TDPM_MODULE_DIR) + "/" + kModule);
#endif
  return out;
}

struct Module {
  ReadOpenVdbFn read = nullptr;
  std::string problem;
};

const Module& openVdbModule() {
  static Module m;
  static std::once_flag once;
  std::call_once(once, [] {
    std::string tried;
    for (const std::string& path : moduleCandidates()) {
      void* h = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!h) {
        tried += (tried.empty() ? "" : "; ") + std::string(::dlerror());
        continue;
      }
      m.read = reinterpret_cast<ReadOpenVdbFn>(::dlsym(h, "tdpm_read_openvdb"));
      if (m.read) return;
      tried += (tried.empty() ? "" : "; ") + path + ": no tdpm_read_openvdb";
    }
    m.problem = "OpenVDB support (" + std::string(kModule) + ") could not be loaded: " + tried;
  });
  return m;
}

}  // namespace

void loadDensityGridFile(scene::DensityGridDesc& grid, const std::string& where, uint64_t maxBytes) {
  RegularFileCheck f = checkRegularFile(grid.file);
  if (!f.ok) throw Error(where + ": density grid file \"" + grid.file + "\": " + f.problem);
  // NanoVDB files start with "NanoVDB0" (its magic number, little endian);
  // everything else goes to OpenVDB, which refuses what is not a .vdb.
  std::FILE* in = nullptr;
  try {
    in = openRegularInput(grid.file, "a density grid file (OpenVDB .vdb or NanoVDB .nvdb)");
  } catch (const Error& e) {
    throw Error(where + ": density grid file " + e.what());
  }
  char magic[8] = {};
  size_t got = std::fread(magic, 1, sizeof magic, in);
  std::fclose(in);
  grid.density.clear();
  if (got == 8 && std::memcmp(magic, "NanoVDB0", 8) == 0) return detail::readNanoVdb(grid, where, maxBytes, f.size);
  const Module& m = openVdbModule();
  if (!m.read) throw Error(where + ": density grid file \"" + grid.file + "\": " + m.problem);
  // The module reports its refusals as text (no exception crosses it).
  std::string error;
  m.read(&grid, &where, maxBytes, &error);
  if (!error.empty()) {
    grid.density.clear();
    throw Error(error);
  }
}

}  // namespace tdpm::media
