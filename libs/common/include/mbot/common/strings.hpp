// Small string helpers the file readers share.
#pragma once

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

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

// The items of `text` between `sep`s, trimmed, empty ones dropped: "a; b;; c" -> {"a", "b", "c"}.
inline std::vector<std::string> SplitTrimmed(const std::string& text, char sep) {
  std::vector<std::string> out;
  for (size_t b = 0; b <= text.size();) {
    const size_t end = std::min(text.find(sep, b), text.size());
    const std::string item = Trim(text.substr(b, end - b));
    if (!item.empty()) out.push_back(item);
    b = end + 1;
  }
  return out;
}

// `v` with at most `digits` significant digits, as an ostream prints it ("14.77", "1e+300", "nan"):
// the one number format of log lines, rubric details and reports.
inline std::string Significant(double v, int digits = 6) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace mbot
