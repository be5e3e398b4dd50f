// Small string helpers the file readers share.
#pragma once

#include <string>

namespace mbot {

// `s` without leading and trailing spaces, tabs, CR and LF (CRLF files read line by line).
inline std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// True when `s` ends with `suffix` (file extensions).
inline bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace mbot
