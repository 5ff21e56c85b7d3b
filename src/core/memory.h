// core/memory.h — what this process holds and what the machine has left:
// peak resident memory (for `tdpm render --stats` and the memory-footprint
// tests) and available memory (for the photon-budget check that runs before
// any tracing, so an impossible budget is an error and not an OOM kill).
// Linux only (getrusage and /proc), like the rest of tdpm.
#pragma once
#include <cstdint>

namespace tdpm {

// Peak resident set size of this process so far, in bytes: VmHWM from
// /proc/self/status, else getrusage's ru_maxrss. 0 if neither is readable.
uint64_t peakResidentBytes();

// Current resident set size (VmRSS), in bytes; 0 if unreadable.
uint64_t currentResidentBytes();

// MemAvailable from /proc/meminfo (the kernel's estimate of what can be
// allocated without swapping), in bytes; 0 if unreadable, in which case
// callers must not treat memory as exhausted.
uint64_t availableMemoryBytes();

}  // namespace tdpm
