// core/temp_dir.cpp — work folders named by pid; stale ones of dead runs removed.
#include "core/temp_dir.h"

#include <dirent.h>
#include <limits.h>
#include <signal.h>  // kill(pid, 0)
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "core/error.h"

namespace tdpm {
namespace {

// mkdtemp's six characters: [A-Za-z0-9].
bool isTempChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

// The pid of an entry named exactly "<prefix><pid>-XXXXXX"; 0 if not one.
long long ownerPid(const std::string& entry, const std::string& prefix) {
  if (entry.size() < prefix.size() + 8 || entry.compare(0, prefix.size(), prefix) != 0) return 0;
  const size_t dash = entry.size() - 7;
  if (entry[dash] != '-') return 0;
  for (size_t i = dash + 1; i < entry.size(); ++i)
    if (!isTempChar(entry[i])) return 0;
  if (dash - prefix.size() > 10) return 0;
  long long pid = 0;
  for (size_t i = prefix.size(); i < dash; ++i) {
    if (entry[i] < '0' || entry[i] > '9') return 0;
    pid = pid * 10 + (entry[i] - '0');
  }
  return pid > 0 && pid <= INT_MAX ? pid : 0;
}

}  // namespace

int removeStaleWorkFolders(const std::string& dir, const std::string& prefix) {
  const std::string base = dir.empty() ? "." : dir;
  std::vector<std::string> stale;
  if (DIR* d = ::opendir(base.c_str())) {
    const long long self = ::getpid();
    while (const struct dirent* e = ::readdir(d)) {
      const long long pid = ownerPid(e->d_name, prefix);
      if (pid == 0 || pid == self) continue;
      if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge (EPERM)
      stale.push_back(e->d_name);
    }
    ::closedir(d);
  }
  int removed = 0;
  for (const std::string& name : stale) {
    const std::string path = base + "/" + name;
    struct stat st;
    // A link of that name is not our folder: never followed, never removed.
    if (::lstat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) continue;
    std::error_code ec;
    std::filesystem::remove_all(path, ec);  // removes links inside, never what they point to
    if (!ec) ++removed;
  }
  return removed;
}

std::string makeWorkFolder(const std::string& dir, const std::string& prefix, const std::string& what) {
  removeStaleWorkFolders(dir, prefix);
  const std::string base = dir.empty() ? "." : dir;
  std::string tmpl = base + "/" + prefix + std::to_string(::getpid()) + "-XXXXXX";
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data()))
    throw Error(what + ": cannot create a temporary directory in '" + base + "' (" + std::strerror(errno) + ")");
  return std::string(buf.data());
}

}  // namespace tdpm
