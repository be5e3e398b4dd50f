// What the running process uses, for the reports of long runs.
#pragma once

#include <cstdint>

namespace mbot {

// Resident memory (RSS) in MB, from /proc/self/statm; 0 where that cannot be read.
double ResidentMemoryMb();
// The address space mapped (what RLIMIT_AS limits) in bytes, from /proc/self/statm; 0 where unknown.
uint64_t AddressSpaceBytes();

}  // namespace mbot
