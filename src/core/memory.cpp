// core/memory.cpp — peak/current RSS and MemAvailable from /proc (getrusage
// as the fallback for the peak).
#include "core/memory.h"

#include <sys/resource.h>

#include <cstdio>
#include <cstring>

namespace tdpm {

namespace {

// The value of "<key>:  <n> kB" in a /proc file, in bytes; 0 if absent.
uint64_t readProcKilobytes(const char* path, const char* key) {
  FILE* f = std::fopen(path, "r");
  if (!f) return 0;
  char line[256];
  size_t keyLen = std::strlen(key);
  uint64_t bytes = 0;
  while (std::fgets(line, sizeof line, f)) {
    if (std::strncmp(line, key, keyLen) != 0 || line[keyLen] != ':') continue;
    unsigned long long kb = 0;
    if (std::sscanf(line + keyLen + 1, "%llu", &kb) == 1) bytes = uint64_t(kb) * 1024;
    break;
  }
  std::fclose(f);
  return bytes;
}

}  // namespace

uint64_t peakResidentBytes() {
  uint64_t hwm = readProcKilobytes("/proc/self/status", "VmHWM");
  if (hwm > 0) return hwm;
  struct rusage ru;
  if (getrusage(RUSAGE_SELF, &ru) == 0 && ru.ru_maxrss > 0) return uint64_t(ru.ru_maxrss) * 1024;  // Linux: kB
  return 0;
}

uint64_t currentResidentBytes() { return readProcKilobytes("/proc/self/status", "VmRSS"); }

uint64_t availableMemoryBytes() { return readProcKilobytes("/proc/meminfo", "MemAvailable"); }

}  // namespace tdpm
