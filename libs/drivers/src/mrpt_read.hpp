// Reading MRPT archives (.gridmap, .simplemap, .rawlog) safely. MRPT's deserialisers size their
// buffers from counts inside the file before the project sees them, and some (the aligned float
// vectors of a range scan) write through a null pointer when the allocation fails. So every MRPT
// file is first read in a forked child with its address space bounded to what the file could
// honestly need: a corrupt count there costs a child, not the machine's memory or the run.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace mbot::drivers {

// The address space a read of an MRPT file of `file_bytes` bytes may add: 64 × the file (gzip
// packs an occupancy grid about 6:1 and MRPT's objects take about twice the bytes they were stored
// in) and never less than 256 MB.
uint64_t MrptReadBudget(uint64_t file_bytes);

// What the trial read in the child found. `records` is what the reader counted (through the pointer
// it was given) before it stopped.
struct MrptTrial {
  bool ok = true;
  std::string reason;  // why not, in words: "it asks for more memory than …", "the reader crashed …"
  uint64_t records = 0;
};

// Runs `read(&records)` in a forked child bounded by MrptReadBudget of the file's size.
MrptTrial TrialReadMrpt(const std::string& path, const std::function<void(uint64_t* records)>& read);

// Checks the file is readable, runs the trial, then `read` for real. Throws std::runtime_error
// ("<path>: cannot read <what>: <cause>") when either fails.
void ReadMrptFile(const std::string& path, const std::string& what, const std::function<void()>& read);

// The line of an MRPT exception that says what went wrong: the innermost "Message:" line (MRPT
// nests the original exception under the one that wraps it), else the first line.
std::string MrptReason(const std::string& what);

}  // namespace mbot::drivers
