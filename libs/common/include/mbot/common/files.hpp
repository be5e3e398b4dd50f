// Input files: one check, one wording, so every reader says why it cannot open a file.
#pragma once

#include <string>

namespace mbot {

// Throws std::runtime_error("<path>: <why>") unless `path` is a regular file this process can open
// for reading, where why is "no such file", "is a directory, not a file", "permission denied" or
// the system's own words for any other failure.
void RequireReadableFile(const std::string& path);

}  // namespace mbot
