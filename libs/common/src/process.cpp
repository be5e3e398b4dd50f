#include "mbot/common/process.hpp"

#include <unistd.h>

#include <fstream>

namespace mbot {

double ResidentMemoryMb() {
  std::ifstream in("/proc/self/statm");
  long long size = 0, resident = 0;
  if (!(in >> size >> resident)) return 0.0;
  return static_cast<double>(resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

}  // namespace mbot
