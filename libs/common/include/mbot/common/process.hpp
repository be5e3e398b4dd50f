// What the running process uses, for the reports of long runs.
#pragma once

namespace mbot {

// Resident memory (RSS) in MB, from /proc/self/statm; 0 where that cannot be read.
double ResidentMemoryMb();

}  // namespace mbot
