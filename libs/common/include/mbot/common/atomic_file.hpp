// Whole-or-nothing file output: write to a temporary file beside the target, then rename, so a
// reader never sees half a file, even when the run is interrupted.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace mbot {

// Calls `write` on a stream to a temporary file in the target's folder and renames it over `path`
// when `write` returns and the stream is good. Throws std::runtime_error naming the path otherwise
// (and leaves any previous file at `path` untouched).
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// Renames an already written temporary file over `path` (for writers that need a file name, such
// as OpenCV's imwrite). `tmp` must be in the same folder.
void CommitFile(const std::string& tmp, const std::string& path);
// A temporary file name beside `path` keeping its extension (so format-by-extension writers work).
std::string TempPathFor(const std::string& path);

// Creates `dir` and its parents; throws naming the folder when it cannot.
void EnsureDirectory(const std::string& dir);

}  // namespace mbot
