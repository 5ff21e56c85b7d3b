// tests/cli_harness.h — runs build/tdpm as a user would (through the shell)
// and captures its exit code and combined output; temporary directories.
#pragma once
#include <dirent.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace tdpm::test {

struct CommandResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, stdout and stderr together, stdin empty.
inline CommandResult runShell(const std::string& commandLine) {
  std::string cmd = commandLine + " 2>&1 < /dev/null";
  CommandResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  int status = pclose(p);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CommandResult runTdpm(const std::string& args) { return runShell(std::string("'") + TDPM_BINARY + "' " + args); }

inline std::string makeTempDir() {
  char tmpl[] = "/tmp/tdpm-test-XXXXXX";
  char* d = mkdtemp(tmpl);
  return d ? std::string(d) : std::string("/tmp");
}

inline bool fileExists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

inline void writeFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// Files in a directory (names), to check nothing half-written is left.
inline int countEntries(const std::string& dir) {
  std::string cmd = "ls -A '" + dir + "' | wc -l";
  FILE* p = popen(cmd.c_str(), "r");
  int n = -1;
  if (p) {
    if (fscanf(p, "%d", &n) != 1) n = -1;
    pclose(p);
  }
  return n;
}

// The names in a directory (without . and ..), in readdir order.
inline std::vector<std::string> folderEntries(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
  }
  return out;
}

// A process id that is certainly not running: a child that has exited and
// been reaped (its pid is free until the kernel hands it out again, which
// it does only after cycling through pid_max).
inline pid_t deadPid() {
  pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

}  // namespace tdpm::test
