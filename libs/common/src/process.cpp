#include "mbot/common/process.hpp"

#include <unistd.h>

#include <fstream>

namespace mbot {

namespace {

// The first two fields of /proc/self/statm, in pages: the address space and the resident set.
bool Statm(uint64_t* size, uint64_t* resident) {
  std::ifstream in("/proc/self/statm");
  return static_cast<bool>(in >> *size >> *resident);
}

}  // namespace

double ResidentMemoryMb() {
  uint64_t size = 0, resident = 0;
  if (!Statm(&size, &resident)) return 0.0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

uint64_t AddressSpaceBytes() {
  uint64_t size = 0, resident = 0;
  if (!Statm(&size, &resident)) return 0;
  return size * static_cast<uint64_t>(sysconf(_SC_PAGESIZE));
}

}  // namespace mbot
