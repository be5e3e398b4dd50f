// Minimal leveled logging to stderr. Warnings carry their context (file, byte offset, channel) in
// the message itself; `WarnOnce` keys repeated warnings so a corrupt log does not flood the terminal.
#pragma once

#include <string>

namespace mbot::log {

enum class Level { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3, kQuiet = 4 };

void SetLevel(Level level);
Level GetLevel();

void Info(const std::string& message);
void Warn(const std::string& message);
void Error(const std::string& message);
// Prints `message` only the first time `key` is seen in this process.
void WarnOnce(const std::string& key, const std::string& message);

// Number of warnings printed (or suppressed by the level) so far; summaries report it.
int WarningCount();

}  // namespace mbot::log
