#include "mbot/common/log.hpp"

#include <unistd.h>

#include <atomic>
#include <iostream>
#include <mutex>
#include <set>

namespace mbot::log {
namespace {
std::atomic<Level> g_level{Level::kInfo};
std::atomic<int> g_warnings{0};
std::mutex g_mutex;
std::set<std::string> g_once;

void Print(Level level, const char* tag, const std::string& message) {
  if (level < g_level.load()) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  // A progress bar may own the current terminal line; start on a fresh one.
  static const bool tty = ::isatty(2);
  if (tty) std::cerr << "\r\033[K";
  std::cerr << tag << message << std::endl;
}
}  // namespace

void SetLevel(Level level) { g_level = level; }
Level GetLevel() { return g_level; }

void Info(const std::string& message) { Print(Level::kInfo, "", message); }
void Warn(const std::string& message) {
  ++g_warnings;
  Print(Level::kWarn, "warning: ", message);
}
void Error(const std::string& message) { Print(Level::kError, "error: ", message); }

void WarnOnce(const std::string& key, const std::string& message) {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (!g_once.insert(key).second) return;
  }
  Warn(message);
}

int WarningCount() { return g_warnings; }

}  // namespace mbot::log
